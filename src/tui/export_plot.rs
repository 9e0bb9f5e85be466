//! `export plot FILE.csv [--all] [--force]`: the signals the Plot pane shows as CSV, one
//! time column (seconds from the trace's start, as the plot's axis) and one column per
//! signal (header: node, object, name, unit); only the visible window unless `--all`.

use super::export::ExportError;
use super::panes::plot::PlotPane;
use crate::analysis::series::{SeriesKey, TimeWindow};
use crate::analysis::trace::Trace;
use crate::od::format_number;
use std::io::Write;
use std::path::Path;

/// The CSV text of `keys` within `window` (None: every point): a row per time any signal
/// has a value; a signal without a value at that time leaves its cell empty. Values are as
/// plotted in the signal's unit (the raw value times the object's scale, never normalised).
pub(crate) fn csv(trace: &Trace, keys: &[SeriesKey], window: Option<TimeWindow>) -> String {
    let t0 = super::panes::start_ns(trace) as f64 / 1e9;
    let mut out = String::from("time_s");
    let mut cells: Vec<(f64, usize, f64)> = Vec::new();
    for (col, key) in keys.iter().enumerate() {
        let Some(line) = trace.series.get(key) else { continue };
        let dict = trace.decoder().dictionary(key.0.node);
        let info = dict.object(key.1, key.2);
        let name = dict.name(key.1, key.2).unwrap_or(&line.name);
        let unit = info
            .and_then(|o| o.unit.as_deref())
            .map(|u| format!(" [{u}]"))
            .unwrap_or_default();
        out.push(',');
        out.push_str(&quoted(&format!(
            "n{} 0x{:04X}:{:02X} {name}{unit}",
            key.0.node, key.1, key.2
        )));
        let scale = info.and_then(|o| o.scale).unwrap_or(1.0);
        let pts = match window {
            Some(w) => line.window(w.start, w.end),
            None => &line.points,
        };
        cells.extend(pts.iter().map(|(t, v)| (*t, col, v * scale)));
    }
    out.push('\n');
    cells.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut row: Vec<String> = vec![String::new(); keys.len()];
    let mut i = 0;
    while i < cells.len() {
        let t = cells[i].0;
        row.iter_mut().for_each(String::clear);
        while i < cells.len() && cells[i].0 == t {
            row[cells[i].1] = format_number(cells[i].2);
            i += 1;
        }
        out.push_str(&format!("{:.6},{}\n", t - t0, row.join(",")));
    }
    out
}

/// A CSV field, quoted when it holds a comma or a quote.
fn quoted(s: &str) -> String {
    if s.contains([',', '"']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// `export plot FILE.csv [--all] [--force]` (the words after `plot`): writes the CSV of the
/// signals `plot` shows; the text says what was written.
pub(crate) fn command(rest: &str, trace: &Trace, plot: &PlotPane) -> Result<String, ExportError> {
    let (mut file, mut all, mut force) = (None, false, false);
    for w in rest.split_whitespace() {
        match w {
            "--all" => all = true,
            "--force" => force = true,
            w if w.starts_with("--") => return Err(ExportError::UnknownOption(w.to_string())),
            w if file.is_none() => file = Some(w.to_string()),
            w => return Err(ExportError::ExtraFile(w.to_string())),
        }
    }
    let file = file.ok_or(ExportError::PlotUsage)?;
    let keys = plot.shown(trace);
    let window = plot.visible_window(trace).ok_or(ExportError::NothingPlotted)?;
    let text = csv(trace, &keys, (!all).then_some(window));
    crate::tui::export::create(Path::new(&file), force)
        .and_then(|mut f| f.write_all(text.as_bytes()))
        .map_err(|source| ExportError::Write {
            file: file.clone(),
            source,
        })?;
    let rows = text.lines().count().saturating_sub(1);
    let what = if all { "all points" } else { "the visible window" };
    Ok(format!(
        "exported {} signals, {rows} rows ({what}) to {file}",
        keys.len()
    ))
}

#[cfg(test)]
mod tests {
    use crate::tui::panes::testutil::constant_and_ramp_app;
    use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

    #[test]
    fn export_plot_writes_time_and_one_column_per_signal() {
        let mut a = constant_and_ramp_app();
        a.run_command("plot 1 6064");
        // The picker adds the velocity.
        for c in "pvel\n".chars() {
            let code = if c == '\n' { KeyCode::Enter } else { KeyCode::Char(c) };
            a.key(KeyEvent::new(code, KeyModifiers::NONE));
        }
        let dir = std::env::temp_dir().join(format!("cotui-plot-csv-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("plot.csv");
        a.run_command(&format!("export plot {}", file.display()));
        let text = std::fs::read_to_string(&file).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[0],
            "time_s,n1 0x6064:00 Position actual value,n1 0x606C:00 Velocity actual value"
        );
        assert_eq!(lines.len(), 41, "{text}");
        assert_eq!(lines[1], "0.018000,4096,0");
        assert_eq!(lines[40], "0.408000,4096,975");
        // An existing file is refused; --force overwrites; --all says so.
        a.run_command(&format!("export plot {}", file.display()));
        assert!(
            a.screen().message().unwrap_or("").contains("add --force"),
            "{:?}",
            a.screen().message()
        );
        a.run_command(&format!("export plot {} --force --all", file.display()));
        assert_eq!(
            a.screen().message(),
            Some(format!("exported 2 signals, 40 rows (all points) to {}", file.display()).as_str())
        );
        a.run_command("export plot");
        assert_eq!(
            a.screen().message(),
            Some("export: usage `export plot FILE.csv [--all] [--force]`")
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}
