//! Messages shared by the parsers of scenario and hand files: I/O errors in a few stable words,
//! TOML errors as one line with its line number, and "did you mean" suggestions for mistyped
//! keys; and [`plural`] for counts in any message or summary. (Its own module so that `hand`
//! and `scenario` need not import each other, nor `report`, `visual` and `summarize` import
//! `batch`.)

/// `[("section.field", value), ...]` for the named fields of `$s`: each key is the field's own
/// name, as serde reads it from the file, so a message cannot name a key the file does not have.
macro_rules! keyed {
    ($section:literal, $s:expr; $($field:ident),+ $(,)?) => {
        [$((concat!($section, ".", stringify!($field)), $s.$field)),+]
    };
}
pub(crate) use keyed;

/// `n thing` or `n things`.
///
/// `pub` (in this private module) only so that `batch` can re-export it for the binary.
pub fn plural(n: usize, thing: &str) -> String {
    if n == 1 {
        format!("1 {thing}")
    } else {
        format!("{n} {thing}s")
    }
}

/// `message` with every number written in more than 24 characters (`1e300` printed in full is
/// 301 digits) rewritten in the shortest exponent form that reads back the same (`1e300`), so
/// that an error line about an absurd value stays one short line (issue 32).
pub(crate) fn short_numbers(message: &str) -> String {
    let mut out = String::with_capacity(message.len().min(512));
    let mut rest = message;
    while let Some(start) = rest.find(|c: char| c.is_ascii_digit()) {
        let len = rest[start..]
            .find(|c: char| !(c.is_ascii_digit() || c == '.'))
            .unwrap_or(rest.len() - start);
        let token = &rest[start..start + len];
        out.push_str(&rest[..start]);
        match token.parse::<f64>() {
            Ok(v) if token.len() > 24 => out.push_str(&format!("{v:e}")),
            _ => out.push_str(token),
        }
        rest = &rest[start + len..];
    }
    out.push_str(rest);
    out
}

/// A short, stable description of an I/O error.
pub(crate) fn io_message(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".to_string(),
        std::io::ErrorKind::PermissionDenied => "permission denied".to_string(),
        std::io::ErrorKind::InvalidData => "not UTF-8 text".to_string(),
        _ => e.to_string(),
    }
}

/// The top-level sections of a scenario, for naming a missing one.
const SECTIONS: [&str; 5] = ["object", "hand", "planner", "sim", "expect"];

/// One line from a TOML error: `line N: `the line`: message`. A missing section is named
/// as such rather than pinned on line 1.
pub(crate) fn toml_message(e: &toml::de::Error, text: &str) -> String {
    let message = with_suggestion(&e.message().replace('\n', " "));
    if let Some(field) = message
        .strip_prefix("missing field `")
        .and_then(|m| m.strip_suffix('`'))
    {
        let at_top = e.span().is_none_or(|s| s.start == 0);
        if at_top && SECTIONS.contains(&field) {
            return format!("missing section `[{field}]`");
        }
    }
    let message = plain_types(&message);
    match e.span() {
        Some(span) => {
            let start = span.start.min(text.len());
            let line_no = text[..start].matches('\n').count() + 1;
            let line = text.lines().nth(line_no - 1).unwrap_or("").trim();
            let message = unknown_section(line, &e.message().replace('\n', " ")).unwrap_or(message);
            if line.is_empty() {
                format!("line {line_no}: {message}")
            } else {
                format!(
                    "line {line_no} (`{}`): {message}",
                    shortened(line, LINE_ECHO_CHARS)
                )
            }
        }
        None => message,
    }
}

/// How much of the offending line a TOML error echoes: a line of 400 KB (issue 32) must not
/// become a 400 KB message.
const LINE_ECHO_CHARS: usize = 80;

/// `s` cut to its first `max` characters, saying how long it was, when it is longer.
fn shortened(s: &str, max: usize) -> String {
    let n = s.chars().count();
    if n <= max {
        s.to_string()
    } else {
        let head: String = s.chars().take(max).collect();
        format!("{head}... ({n} characters)")
    }
}

/// serde's Rust type names in a message (`expected f64`) in the words of a TOML file.
fn plain_types(message: &str) -> String {
    let mut m = message.to_string();
    for (rust, plain) in [
        ("expected f64", "expected a number"),
        ("expected f32", "expected a number"),
        ("expected usize", "expected a whole number"),
        ("expected u64", "expected a whole number"),
        ("expected u32", "expected a whole number"),
        ("expected i64", "expected a whole number"),
        ("wanted string or table", "expected a name in quotes"),
    ] {
        m = m.replace(rust, plain);
    }
    m
}

/// For a section header such as `[simm]` that names no section: "unknown section `[simm]`"
/// and the nearest known key as a section (or, with none near, the keys serde expected).
/// `None` for anything else.
fn unknown_section(line: &str, message: &str) -> Option<String> {
    let header = line.strip_prefix('[')?.split(']').next()?.trim();
    let (unknown, known) = unknown_field(message)?;
    if header != unknown || header.contains('.') {
        return None;
    }
    let (_, expected) = message.strip_prefix("unknown field `")?.split_once('`')?;
    Some(match did_you_mean(unknown, known) {
        Some(k) => format!("unknown section `[{unknown}]`; did you mean `[{k}]`?"),
        None => format!("unknown section `[{unknown}]`{expected}"),
    })
}

/// The unknown key and the keys expected instead, from serde's "unknown field `x`, expected
/// one of `a`, `b`, ..." (or "expected `a`"); `None` for any other message.
pub(crate) fn unknown_field(message: &str) -> Option<(&str, Vec<&str>)> {
    let (unknown, expected) = message.strip_prefix("unknown field `")?.split_once('`')?;
    Some((unknown, expected.split('`').skip(1).step_by(2).collect()))
}

/// `message` with "; did you mean `key`?" appended when it is serde's "unknown field `x`,
/// expected one of `a`, `b`, ..." (or "expected `a`") and one known key is close to `x`.
pub(crate) fn with_suggestion(message: &str) -> String {
    let Some((unknown, known)) = unknown_field(message) else {
        return message.to_string();
    };
    match did_you_mean(unknown, known) {
        Some(k) => format!("{message}; did you mean `{k}`?"),
        None => message.to_string(),
    }
}

/// The known key nearest to `unknown` by edit distance (case-insensitive), when it is close
/// enough to be a typo: at most a third of the longer name's characters differ (at least 1,
/// at most 3). The first of equally near keys wins, so the answer is deterministic.
pub(crate) fn did_you_mean<'a>(
    unknown: &str,
    known: impl IntoIterator<Item = &'a str>,
) -> Option<&'a str> {
    let u = unknown.to_lowercase();
    let mut best: Option<(usize, &'a str)> = None;
    for k in known {
        let d = edit_distance(&u, &k.to_lowercase());
        let limit = (u.chars().count().max(k.chars().count()) / 3).clamp(1, 3);
        if d <= limit && best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, k));
        }
    }
    best.map(|(_, k)| k)
}

/// Levenshtein distance (insertions, deletions, substitutions), with a swap of two adjacent
/// characters counted as one edit (Damerau, optimal string alignment): `lenght` → `length` is 1.
fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, cell) in d[0].iter_mut().enumerate() {
        *cell = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut v = (d[i - 1][j] + 1)
                .min(d[i][j - 1] + 1)
                .min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                v = v.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = v;
        }
    }
    d[a.len()][b.len()]
}

#[cfg(test)]
mod tests {
    use super::{did_you_mean, edit_distance, toml_message};

    #[test]
    fn absurd_numbers_are_written_short() {
        let long = format!("must be in (0, 2], got {}", 1e300);
        assert_eq!(long.len(), 23 + 301);
        assert_eq!(super::short_numbers(&long), "must be in (0, 2], got 1e300");
        let m = format!("got {} and {}", 123456.5, 1.5e-300);
        assert_eq!(super::short_numbers(&m), "got 123456.5 and 1.5e-300");
    }

    #[test]
    fn a_huge_offending_line_is_echoed_in_part() {
        // Issue 32: a 400 KB line with an error was echoed whole, a 400 KB message.
        let huge = format!(
            "[object]\nmesh = \"a.stl\"\nfriction = 0.3 {}\n",
            "x".repeat(400_000)
        );
        let e = toml::from_str::<toml::Table>(&huge).expect_err("junk after a value");
        let m = toml_message(&e, &huge);
        assert!(
            m.starts_with("line 3 (`friction = 0.3 xxx"),
            "{}",
            &m[..m.len().min(200)]
        );
        assert!(m.len() < 300, "{} bytes", m.len());
        assert!(
            m.contains("(400015 characters)"),
            "{}",
            &m[..m.len().min(300)]
        );
        // A short line is echoed whole.
        let short = "[object]\nfriction = 0.3 x\n";
        let e = toml::from_str::<toml::Table>(short).expect_err("junk after a value");
        let m = toml_message(&e, short);
        assert!(m.starts_with("line 2 (`friction = 0.3 x`): "), "{m}");
    }

    #[test]
    fn near_keys_are_suggested_and_far_ones_not() {
        assert_eq!(edit_distance("lenght", "length"), 1);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("planer", "planner"), 1);
        let keys = ["mesh", "units", "density_kg_m3", "mass_kg", "friction"];
        assert_eq!(did_you_mean("densty_kg_m3", keys), Some("density_kg_m3"));
        assert_eq!(did_you_mean("Units", keys), Some("units"));
        assert_eq!(did_you_mean("colour", keys), None);
        assert_eq!(did_you_mean("", keys), None);
    }
}
