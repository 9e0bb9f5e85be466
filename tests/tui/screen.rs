//! The in-process analyzer as text: its screen drawn on a TestBackend, and a wait for what
//! it shows.

use cotui::tui::app::App;
use ratatui::Terminal;
use ratatui::backend::TestBackend;
use std::time::{Duration, Instant};

/// The whole screen as text, at `w`x`h`.
pub fn screen_at(a: &mut App, w: u16, h: u16) -> String {
    let mut term = Terminal::new(TestBackend::new(w, h)).unwrap();
    term.draw(|f| cotui::tui::ui::draw(f, a)).unwrap();
    let buf = term.backend().buffer().clone();
    (0..buf.area.height)
        .map(|y| {
            (0..buf.area.width)
                .map(|x| buf[(x, y)].symbol().to_string())
                .collect::<String>()
                + "\n"
        })
        .collect()
}

/// Takes frames in until `f` holds on the `w`x`h` screen (90 s at most: the machine may be
/// busy); the screen.
pub fn until_at(a: &mut App, (w, h): (u16, u16), what: &str, f: impl Fn(&App, &str) -> bool) -> String {
    let start = Instant::now();
    loop {
        a.ingest(Duration::from_millis(20));
        let s = screen_at(a, w, h);
        if f(a, &s) {
            return s;
        }
        assert!(
            start.elapsed() < Duration::from_secs(90),
            "timed out waiting for {what}:\n{s}"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}
