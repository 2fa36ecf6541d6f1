//! A study's CSV text read back as records: the README and `map.svg` take
//! every number they show from the files written beside them.

/// One CSV's records, by column name.
pub type Records = Vec<std::collections::BTreeMap<String, String>>;

/// Parses CSV text with a header row (no quoting: the studies write none).
pub fn parse(text: &str) -> Records {
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    lines
        .map(|l| {
            head.iter()
                .zip(l.split(','))
                .map(|(h, v)| (h.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

/// The number in column `key` (NaN where blank or absent).
pub fn num(r: &std::collections::BTreeMap<String, String>, key: &str) -> f64 {
    r.get(key).and_then(|v| v.parse().ok()).unwrap_or(f64::NAN)
}
