//! `cotui bench --tui`: figures of the interactive analyzer on a generated log, measured
//! in-process with the same loop turn as the terminal ([`crate::tui::term::step`]) drawing
//! to an off-screen 160×50 TestBackend.
//!
//! - first screen: from starting to read the log to the first drawn screen with frames;
//! - full index: until every frame is in the trace store;
//! - memory: store bytes per frame, and the process's peak RSS per frame;
//! - redraw: a draw with nothing new, a draw after paging back (rows decoded anew), a
//!   draw with a filter in force;
//! - filter over the whole log: from setting a filter to its last row, for a filter on
//!   stored fields (`node 2 or id 700-77f`) and one that decodes SDO and PDO frames
//!   (`6041 or 6060`);
//! - search over the whole log for a label text no frame has (every frame decoded), in
//!   the background: its time and the loop turns (draw included) meanwhile, 99th
//!   percentile and longest;
//! - key response while replaying at full speed: from a key press to the end of the
//!   draw that shows it, i.e. one loop turn (ingest budget, filter budget, draw).

use crate::analysis::trace::Trace;
use crate::decode::Decoder;
use crate::od::Dictionary;
use crate::tui::app::{App, SourceInfo, SourceKind};
use crate::tui::keymap::{Action, Keymap};
use crate::tui::source;
use crate::tui::term::{WORK_BUDGET, step};
use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::Terminal;
use ratatui::backend::TestBackend;
use std::time::{Duration, Instant};

fn app_for(feed: source::Feeds, kind: SourceKind) -> App {
    let trace = Trace::new(Decoder::new(Dictionary::default(), Vec::new()), 500_000);
    App::new(
        trace,
        Keymap::default_map(),
        SourceInfo::new("bench.log", kind, feed.0, feed.1),
    )
}

/// CPU time of this thread in milliseconds (what a loop turn costs, whatever the load).
fn thread_cpu_ms() -> f64 {
    // SAFETY: timespec is plain data that clock_gettime fills.
    let mut ts: libc::timespec = unsafe { std::mem::zeroed() };
    // SAFETY: a valid clock id and a valid pointer.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 * 1e3 + ts.tv_nsec as f64 / 1e6
}

/// 99th percentile and maximum of `v` (sorted in place).
fn p99_max(v: &mut [f64]) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    (
        v.get(v.len() * 99 / 100).copied().unwrap_or(0.0),
        v.last().copied().unwrap_or(0.0),
    )
}

fn peak_rss_kib() -> u64 {
    // SAFETY: rusage is plain data that getrusage fills.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: RUSAGE_SELF with a valid pointer.
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    u.ru_maxrss as u64
}

/// Mean and maximum of `n` timed runs of `f`, in milliseconds.
fn time_ms(n: usize, mut f: impl FnMut()) -> (f64, f64) {
    let mut max: f64 = 0.0;
    let start = Instant::now();
    for _ in 0..n {
        let t = Instant::now();
        f();
        max = max.max(t.elapsed().as_secs_f64() * 1e3);
    }
    (start.elapsed().as_secs_f64() * 1e3 / n as f64, max)
}

/// Seconds from setting `filter` until the whole trace is scanned, in the loop's slices.
fn filter_seconds(app: &mut App, filter: &str) -> f64 {
    let start = Instant::now();
    app.set_filter(filter);
    while app.work(WORK_BUDGET) {}
    start.elapsed().as_secs_f64()
}

/// Runs the benchmark on `frames` generated frames.
pub fn bench(frames: u64, json: bool) -> std::io::Result<()> {
    let dir = std::env::temp_dir().join(format!("cotui-bench-tui-{}", std::process::id()));
    let scratch =
        super::scratch::Scratch::create(dir, super::need_bytes(frames as f64 * super::log::bytes_per_frame()))?;
    let log = scratch.path().join("bench.log");
    super::log::write_log(&log, frames)?;
    let rss_before = peak_rss_kib();
    let mut term = Terminal::new(TestBackend::new(160, 50)).map_err(std::io::Error::other)?;
    let draw = |term: &mut Terminal<TestBackend>, app: &mut App| {
        term.draw(|f| crate::tui::ui::draw(f, app))
            .map(|_| ())
            .map_err(std::io::Error::other)
    };

    // Open: first screen and full index.
    let start = Instant::now();
    let mut app = app_for((source::open(log.clone(), None), None), SourceKind::Open);
    let mut first_screen = None;
    while !app.source().done {
        step(&mut app);
        if first_screen.is_none() && !app.trace().is_empty() {
            draw(&mut term, &mut app)?;
            first_screen = Some(start.elapsed().as_secs_f64());
        }
    }
    let indexed = start.elapsed().as_secs_f64();
    let n = app.trace().len();
    let store_per_frame = app.trace().store.bytes() as f64 / n.max(1) as f64;
    let rss_per_frame = (peak_rss_kib().saturating_sub(rss_before)) as f64 * 1024.0 / n.max(1) as f64;

    // Redraw figures with the whole log loaded.
    draw(&mut term, &mut app)?;
    let idle = time_ms(200, || {
        let _ = draw(&mut term, &mut app);
    });
    let page_back = time_ms(200, || {
        app.act(Action::PageUp);
        let _ = draw(&mut term, &mut app);
    });
    app.set_filter("node 3 kind tpdo");
    while app.work(Duration::from_millis(100)) {}
    app.act(Action::Bottom);
    let filtered = time_ms(200, || {
        app.act(Action::PageUp);
        let _ = draw(&mut term, &mut app);
    });
    let filter_fields = filter_seconds(&mut app, "node 2 or id 700-77f");
    let filter_decoded = filter_seconds(&mut app, "6041 or 6060");
    app.set_filter("");
    app.act(Action::Top);
    let start = Instant::now();
    app.run_command("search \"no such label\"");
    let (mut turns, mut cpu) = (Vec::new(), Vec::new());
    while app.screen().search().is_some_and(|s| !s.complete(app.trace())) {
        let (t, c) = (Instant::now(), thread_cpu_ms());
        step(&mut app);
        draw(&mut term, &mut app)?;
        turns.push(t.elapsed().as_secs_f64() * 1e3);
        cpu.push(thread_cpu_ms() - c);
    }
    let search = start.elapsed().as_secs_f64();
    let search_turn = p99_max(&mut turns);
    let search_cpu = p99_max(&mut cpu);
    drop(app);

    // Key response while replaying as fast as possible.
    let (rx, ctl) = source::replay(log.clone(), 0.0, None);
    let mut app = app_for((rx, Some(ctl)), SourceKind::Replay { speed: 0.0 });
    let mut responses = Vec::new();
    let down = KeyEvent::new(KeyCode::Down, KeyModifiers::NONE);
    let replay_start = Instant::now();
    while !app.source().done && responses.len() < 200 {
        let t = Instant::now();
        app.key(down);
        step(&mut app);
        draw(&mut term, &mut app)?;
        responses.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let replayed = app.trace().len();
    let replay_rate = replayed as f64 / replay_start.elapsed().as_secs_f64();
    drop(app);
    drop(scratch);
    let key_mean = responses.iter().sum::<f64>() / responses.len().max(1) as f64;
    let key_max = responses.iter().copied().fold(0.0, f64::max);
    let key_p99 = p99_max(&mut responses).0;
    let first = first_screen.unwrap_or(f64::NAN);

    if json {
        println!(
            "{}",
            serde_json::json!({
                "frames": n, "first_screen_s": first, "full_index_s": indexed,
                "store_bytes_per_frame": store_per_frame, "peak_rss_bytes_per_frame": rss_per_frame,
                "redraw_idle_ms": {"mean": idle.0, "max": idle.1},
                "redraw_page_back_ms": {"mean": page_back.0, "max": page_back.1},
                "redraw_filtered_ms": {"mean": filtered.0, "max": filtered.1},
                "filter_fields_s": filter_fields, "filter_decoded_s": filter_decoded,
                "search_s": search,
                "search_loop_turn_ms": {"p99": search_turn.0, "max": search_turn.1},
                "search_loop_turn_cpu_ms": {"p99": search_cpu.0, "max": search_cpu.1},
                "key_response_ms": {"mean": key_mean, "p99": key_p99, "max": key_max, "samples": responses.len()},
                "replay_frames_per_s": replay_rate,
            })
        );
        return Ok(());
    }
    println!("cotui bench --tui: {n} generated frames (candump -l log), 160x50 off-screen terminal");
    println!("  first screen            {:>9.3} s   (target <= 0.3 s)", first);
    println!(
        "  full index              {:>9.3} s   ({:.0} frames/s; target <= 10 s for 50 M frames: >= 5 M frames/s)",
        indexed,
        n as f64 / indexed
    );
    println!(
        "  trace store             {:>9.1} bytes/frame (target <= 32)",
        store_per_frame
    );
    println!(
        "  peak RSS growth         {:>9.1} bytes/frame (target <= 32: everything, store, checkpoints, queues)",
        rss_per_frame
    );
    println!(
        "  redraw, nothing new     {:>9.3} ms mean {:>8.3} ms max (target < 5 ms)",
        idle.0, idle.1
    );
    println!(
        "  redraw after page up    {:>9.3} ms mean {:>8.3} ms max",
        page_back.0, page_back.1
    );
    println!(
        "  redraw, filter in force {:>9.3} ms mean {:>8.3} ms max",
        filtered.0, filtered.1
    );
    println!(
        "  filter, stored fields   {:>9.3} s   ({:.0} frames/s; node 2 or id 700-77f)",
        filter_fields,
        n as f64 / filter_fields
    );
    println!(
        "  filter, decoded objects {:>9.3} s   ({:.0} frames/s; 6041 or 6060)",
        filter_decoded,
        n as f64 / filter_decoded
    );
    println!(
        "  search, every label     {:>9.3} s   ({:.0} frames/s; loop turn meanwhile {:.1} ms p99 (target < 50 ms), {:.1} ms max; CPU {:.1} ms p99, {:.1} ms max)",
        search,
        n as f64 / search,
        search_turn.0,
        search_turn.1,
        search_cpu.0,
        search_cpu.1
    );
    println!(
        "  key response, replaying {:>9.3} ms mean {:>8.3} ms p99 {:>8.3} ms max over {} keys at {:.0} frames/s (target p99 < 50 ms)",
        key_mean,
        key_p99,
        key_max,
        responses.len(),
        replay_rate
    );
    Ok(())
}
