//! The key a TOML syntax error is about, for the error message.

/// Best-effort dotted key for a TOML syntax error: the key on the line the
/// error points at, prefixed by its table header.
pub(super) fn key_of_toml_error(text: &str, span: Option<std::ops::Range<usize>>) -> String {
    let Some(span) = span else {
        return "toml".into();
    };
    let start = span.start.min(text.len());
    let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
    let line = text[line_start..].lines().next().unwrap_or("");
    let header = line.trim_start();
    if header.starts_with('[') && start > line_start + (line.len() - header.len()) {
        // Inside a table header (a duplicate table): that table is the key.
        return header
            .trim_start_matches('[')
            .split(']')
            .next()
            .unwrap_or("")
            .trim()
            .to_string();
    }
    let table = header_before(text, line_start);
    match line.split_once('=') {
        Some((k, _)) if !line.trim_start().starts_with('[') => {
            let k = k.trim();
            match table {
                Some(t) => format!("{t}.{k}"),
                None => k.to_string(),
            }
        }
        _ => table.unwrap_or_else(|| "toml".into()),
    }
}

/// The last table header before `pos`, without its brackets.
fn header_before(text: &str, pos: usize) -> Option<String> {
    text[..pos.min(text.len())]
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| l.starts_with('['))
        .map(|l| l.trim_matches(|c| c == '[' || c == ']').trim().to_string())
}
