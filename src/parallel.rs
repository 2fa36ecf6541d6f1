//! Rows of a fixed task list evaluated in parallel (rayon), in order, with a
//! progress bar: how `report` and `study` compute their cells.

use std::io::IsTerminal;

use rayon::prelude::*;

/// A progress bar on stderr: hidden when not a terminal, when `CI` is set,
/// or when the caller turned it off.
pub fn progress(len: u64, show: bool, what: &str) -> indicatif::ProgressBar {
    let visible = show && std::io::stderr().is_terminal() && std::env::var_os("CI").is_none();
    if !visible {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(len);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{msg:>10} [{bar:40}] {pos}/{len} cells, {elapsed} elapsed, eta {eta}",
    ) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(what.to_string());
    bar
}

/// Evaluates `eval` on every item in parallel (rayon), keeping their order,
/// with a [`progress`] bar named `what`.
pub fn par_rows<T: Sync>(
    items: &[T],
    show_progress: bool,
    what: &str,
    eval: impl Fn(&T) -> Vec<f64> + Sync,
) -> Vec<Vec<f64>> {
    let bar = progress(items.len() as u64, show_progress, what);
    let rows: Vec<Vec<f64>> = items
        .par_iter()
        .map(|t| {
            let r = eval(t);
            bar.inc(1);
            r
        })
        .collect();
    bar.finish_and_clear();
    rows
}
