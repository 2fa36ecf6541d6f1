//! The numeric CSV pushval reads (an outside engine's standard output,
//! `compare`'s and `fit`'s trajectory files): a header naming the columns,
//! then rows of comma-separated fields. Parsed by hand: the format is fixed
//! and numeric, and every error names the line and the column.

/// One data row: its line number (1-based, in the whole text), the text
/// columns and the numeric columns asked for, in the order asked.
#[derive(Debug, Clone, PartialEq)]
pub struct Record<'a> {
    /// Line number in the text (1-based).
    pub line: usize,
    /// The text columns' fields, trimmed.
    pub labels: Vec<&'a str>,
    /// The numeric columns' values (finite).
    pub numbers: Vec<f64>,
}

/// A malformed CSV text: where and what.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CsvError {
    /// Line number (1-based); 0 when the text is empty.
    pub line: usize,
    /// The column, when one field is at fault.
    pub column: Option<String>,
    /// What is wrong.
    pub problem: String,
}

impl std::fmt::Display for CsvError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (self.line, &self.column) {
            (0, _) => write!(f, "{}", self.problem),
            (n, Some(c)) => write!(f, "line {n}: column `{c}`: {}", self.problem),
            (n, None) => write!(f, "line {n}: {}", self.problem),
        }
    }
}

impl std::error::Error for CsvError {}

/// Reads `text`: the first non-blank line is the header, which must hold
/// every column of `labels` (text) and `numbers` (finite numbers), in any
/// order; further columns are ignored. Blank lines are skipped. Every row
/// must have as many fields as the header.
pub fn read<'a>(
    text: &'a str,
    labels: &[&str],
    numbers: &[&str],
) -> Result<Vec<Record<'a>>, CsvError> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((h, header)) = lines.next() else {
        return Err(CsvError {
            line: 0,
            column: None,
            problem: "no header and no rows (empty)".into(),
        });
    };
    let cols: Vec<&str> = header.split(',').map(str::trim).collect();
    let need = labels
        .iter()
        .chain(numbers)
        .copied()
        .collect::<Vec<_>>()
        .join(",");
    let find = |name: &str| {
        cols.iter()
            .position(|c| *c == name)
            .ok_or_else(|| CsvError {
                line: h + 1,
                column: None,
                problem: format!("the header lacks the column `{name}` (need {need})"),
            })
    };
    let il: Vec<usize> = labels.iter().map(|c| find(c)).collect::<Result<_, _>>()?;
    let inum: Vec<usize> = numbers.iter().map(|c| find(c)).collect::<Result<_, _>>()?;
    let mut out = Vec::new();
    for (n, line) in lines {
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        if f.len() != cols.len() {
            return Err(CsvError {
                line: n + 1,
                column: None,
                problem: format!("{} fields, the header has {}", f.len(), cols.len()),
            });
        }
        let mut values = Vec::with_capacity(inum.len());
        for &i in &inum {
            let bad = |problem: String| CsvError {
                line: n + 1,
                column: Some(cols[i].to_string()),
                problem,
            };
            let v: f64 = f[i]
                .parse()
                .map_err(|_| bad(format!("`{}` is not a number", f[i])))?;
            if !v.is_finite() {
                return Err(bad(format!("{v} is not finite")));
            }
            values.push(v);
        }
        out.push(Record {
            line: n + 1,
            labels: il.iter().map(|&i| f[i]).collect(),
            numbers: values,
        });
    }
    Ok(out)
}
