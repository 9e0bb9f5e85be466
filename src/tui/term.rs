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
    // A hung-up terminal can keep crossterm's input poll from returning; after a signal
    // the loop gets half a second to finish, then this watchdog restores and exits.
    std::thread::spawn(|| {
        while !STOP.load(Ordering::SeqCst) {
            std::thread::sleep(Duration::from_millis(50));
        }
        std::thread::sleep(Duration::from_millis(500));
        let _ = execute!(stdout(), DisableMouseCapture);
        ratatui::restore();
        std::process::exit(0);
    });
    // ratatui::init installs a panic hook that restores the terminal before the message.
    let mut terminal = ratatui::init();
    let _ = execute!(stdout(), EnableMouseCapture);
    let result = event_loop(&mut terminal, &mut app);
    let _ = execute!(stdout(), DisableMouseCapture);
    ratatui::restore();
    result
}

/// Time per loop turn for taking in frames.
pub const INGEST_BUDGET: Duration = Duration::from_millis(12);
/// Time per loop turn for filter scanning.
pub const WORK_BUDGET: Duration = Duration::from_millis(8);

/// One turn of background work: take in frames, scan filters, update rates. True when
/// more is waiting (the loop then polls input without sleeping).
pub fn step(app: &mut App) -> bool {
    let more_input = app.ingest(INGEST_BUDGET);
    let more_work = app.work(WORK_BUDGET);
    app.tick();
    more_input || more_work
}

fn event_loop(terminal: &mut ratatui::DefaultTerminal, app: &mut App) -> Result<(), String> {
    let mut last_draw = Instant::now() - FRAME;
    // Input is answered at once; frames alone redraw at most every FRAME.
    let mut input = false;
    loop {
        let busy = step(app);
        if app.dirty && (input || last_draw.elapsed() >= FRAME) {
            terminal.draw(|f| ui::draw(f, app)).map_err(|e| e.to_string())?;
            app.dirty = false;
            input = false;
            last_draw = Instant::now();
        }
        let wait = if busy {
            Duration::ZERO
        } else {
            Duration::from_millis(20)
        };
        if event::poll(wait).map_err(|e| e.to_string())? {
            // Take every pending event before the next draw.
            loop {
                match event::read().map_err(|e| e.to_string())? {
                    Event::Key(k) if k.kind != KeyEventKind::Release => {
                        app.key(k);
                        input = true;
                    }
                    Event::Mouse(m) => {
                        app.mouse(m);
                        input = true;
                    }
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
