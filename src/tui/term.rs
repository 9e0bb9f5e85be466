//! The terminal: raw mode, alternate screen and mouse on entry; always restored on exit,
//! panic, Ctrl-C, SIGTERM and SIGQUIT. Suspending (ctrl-z, or SIGTSTP from outside)
//! restores it before the process stops; on SIGCONT it is set up again and redrawn.
//! Input is read only when stdin is a terminal.

use super::app::App;
use super::ui;
use crossterm::clipboard::CopyToClipboard;
use crossterm::event::{
    self, DisableMouseCapture, EnableMouseCapture, Event, KeyCode, KeyEvent, KeyEventKind, KeyModifiers,
};
use crossterm::execute;
use crossterm::terminal::{EnterAlternateScreen, enable_raw_mode};
use std::io::{IsTerminal, stdout};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Set by SIGTERM / SIGINT / SIGHUP / SIGQUIT.
static STOP: AtomicBool = AtomicBool::new(false);

/// Set by SIGTSTP: the loop restores the terminal, then stops the process.
static SUSPEND: AtomicBool = AtomicBool::new(false);

extern "C" fn on_signal(_: libc::c_int) {
    STOP.store(true, Ordering::SeqCst);
}

extern "C" fn on_suspend(_: libc::c_int) {
    SUSPEND.store(true, Ordering::SeqCst);
}

/// Installs `handler` for `sig`.
fn catch(sig: libc::c_int, handler: extern "C" fn(libc::c_int)) {
    // SAFETY: the handlers only store to an atomic, which is async-signal-safe.
    unsafe {
        libc::signal(sig, handler as *const () as libc::sighandler_t);
    }
}

/// Why the terminal loop could not run or stopped.
#[derive(Debug, thiserror::Error)]
pub enum TermError {
    /// Stdin or stdout is not a terminal.
    #[error("the interactive analyzer needs a terminal (use `cotui decode` for pipes)")]
    NotATerminal,
    /// Raw mode or the alternate screen could not be set up.
    #[error("cannot set up the terminal: {0}")]
    Setup(std::io::Error),
    /// Drawing or reading input failed.
    #[error(transparent)]
    Io(#[from] std::io::Error),
}

/// Least time between two draws.
const FRAME: Duration = Duration::from_millis(33);

/// Runs `app` in the terminal until the user quits; the terminal is restored on every way out.
pub fn run(mut app: App) -> Result<(), TermError> {
    if !std::io::stdin().is_terminal() || !stdout().is_terminal() {
        return Err(TermError::NotATerminal);
    }
    for sig in [libc::SIGTERM, libc::SIGINT, libc::SIGHUP, libc::SIGQUIT] {
        catch(sig, on_signal);
    }
    catch(libc::SIGTSTP, on_suspend);
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
    // ratatui::try_init installs a panic hook that restores the terminal before the message.
    let mut terminal = ratatui::try_init().map_err(TermError::Setup)?;
    let ratatui_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let _ = execute!(stdout(), DisableMouseCapture);
        ratatui_hook(info);
    }));
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

/// Ctrl-z: in raw mode the terminal sends it as a key, not as SIGTSTP.
fn is_suspend(k: &KeyEvent) -> bool {
    k.code == KeyCode::Char('z') && k.modifiers.contains(KeyModifiers::CONTROL)
}

/// Gives the shell its terminal back and stops the process as SIGTSTP does; once
/// continued (`fg`), takes the terminal again and has the next draw repaint all of it.
fn suspend(terminal: &mut ratatui::DefaultTerminal) -> Result<(), TermError> {
    let _ = execute!(stdout(), DisableMouseCapture);
    ratatui::restore();
    // SAFETY: the default action of SIGTSTP stops the process (the whole process, as the
    // shell expects); it returns here on SIGCONT, and the handler is set again.
    unsafe {
        libc::signal(libc::SIGTSTP, libc::SIG_DFL);
        libc::raise(libc::SIGTSTP);
    }
    catch(libc::SIGTSTP, on_suspend);
    SUSPEND.store(false, Ordering::SeqCst);
    enable_raw_mode().map_err(TermError::Setup)?;
    execute!(stdout(), EnterAlternateScreen, EnableMouseCapture).map_err(TermError::Setup)?;
    terminal.clear()?;
    Ok(())
}

fn event_loop(terminal: &mut ratatui::DefaultTerminal, app: &mut App) -> Result<(), TermError> {
    let mut last_draw = Instant::now() - FRAME;
    // Input is answered at once; frames alone redraw at most every FRAME.
    let mut input = false;
    loop {
        let busy = step(app);
        if app.dirty() && (input || last_draw.elapsed() >= FRAME) {
            terminal.draw(|f| ui::draw(f, app))?;
            app.drawn();
            input = false;
            last_draw = Instant::now();
        }
        let wait = if busy {
            Duration::ZERO
        } else {
            Duration::from_millis(20)
        };
        if event::poll(wait)? {
            // Take every pending event before the next draw.
            loop {
                match event::read()? {
                    Event::Key(k) if k.kind != KeyEventKind::Release && is_suspend(&k) => {
                        SUSPEND.store(true, Ordering::SeqCst);
                        break;
                    }
                    Event::Key(k) if k.kind != KeyEventKind::Release => {
                        app.key(k);
                        input = true;
                    }
                    Event::Mouse(m) => {
                        app.mouse(m);
                        input = true;
                    }
                    Event::Resize(..) => app.redraw(),
                    _ => {}
                }
                if !event::poll(Duration::ZERO)? {
                    break;
                }
            }
        }
        if let Some(text) = app.screen_mut().take_clipboard() {
            // OSC 52: a terminal that does not support it ignores the sequence.
            let _ = execute!(stdout(), CopyToClipboard::to_clipboard_from(text));
        }
        if app.quits() || STOP.load(Ordering::SeqCst) {
            return Ok(());
        }
        if SUSPEND.load(Ordering::SeqCst) {
            suspend(terminal)?;
            app.redraw();
            input = true;
        }
    }
}
