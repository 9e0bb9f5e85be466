//! The terminal: raw mode, alternate screen and mouse on entry; always restored on exit,
//! panic, Ctrl-C and SIGTERM. Input is read only when stdin is a terminal.

use super::app::App;
use super::ui;
use crossterm::event::{self, DisableMouseCapture, EnableMouseCapture, Event, KeyEventKind};
use crossterm::execute;
use std::io::{IsTerminal, stdout};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Set by SIGTERM / SIGINT / SIGHUP.
static STOP: AtomicBool = AtomicBool::new(false);

extern "C" fn on_signal(_: libc::c_int) {
    STOP.store(true, Ordering::SeqCst);
}

/// Least time between two draws.
const FRAME: Duration = Duration::from_millis(33);

/// Runs `app` in the terminal until the user quits; the terminal is restored on every way out.
pub fn run(mut app: App) -> Result<(), String> {
    if !std::io::stdin().is_terminal() || !stdout().is_terminal() {
        return Err("the interactive analyzer needs a terminal (use `cotui decode` for pipes)".into());
    }
    for sig in [libc::SIGTERM, libc::SIGINT, libc::SIGHUP] {
        // SAFETY: the handler only stores to an atomic, which is async-signal-safe.
        unsafe {
            libc::signal(sig, on_signal as *const () as libc::sighandler_t);
        }
    }
    // ratatui::init installs a panic hook that restores the terminal before the message.
    let mut terminal = ratatui::init();
    let _ = execute!(stdout(), EnableMouseCapture);
    let result = event_loop(&mut terminal, &mut app);
    let _ = execute!(stdout(), DisableMouseCapture);
    ratatui::restore();
    result
}

fn event_loop(terminal: &mut ratatui::DefaultTerminal, app: &mut App) -> Result<(), String> {
    let mut last_draw = Instant::now() - FRAME;
    loop {
        let more_input = app.ingest(Duration::from_millis(12));
        let more_work = app.work(Duration::from_millis(8));
        app.tick();
        if app.dirty && last_draw.elapsed() >= FRAME {
            terminal.draw(|f| ui::draw(f, app)).map_err(|e| e.to_string())?;
            app.dirty = false;
            last_draw = Instant::now();
        }
        let wait = if more_input || more_work {
            Duration::ZERO
        } else {
            Duration::from_millis(20)
        };
        if event::poll(wait).map_err(|e| e.to_string())? {
            // Take every pending event before the next draw.
            loop {
                match event::read().map_err(|e| e.to_string())? {
                    Event::Key(k) if k.kind != KeyEventKind::Release => app.key(k),
                    Event::Mouse(m) => app.mouse(m),
                    Event::Resize(..) => app.dirty = true,
                    _ => {}
                }
                if !event::poll(Duration::ZERO).map_err(|e| e.to_string())? {
                    break;
                }
            }
        }
        if app.quit || STOP.load(Ordering::SeqCst) {
            return Ok(());
        }
    }
}
