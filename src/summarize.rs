//! `grasp-sim summarize`: a dataset report from a batch's JSON Lines, so nobody needs jq to
//! read a run.
//!
//! Input: lines written by `batch` (or by `grasp-sim --json`): run reports (DESIGN.md §6) and
//! `{"scenario", "error"}` lines. Output: the counts (planned, ungraspable, errors; hold, slip,
//! drop; held per gravity direction; expectations), the slowest objects, and a CSV with one row
//! per object in file order. A last line without its newline (a run interrupted while writing)
//! is not taken as data: it is skipped with a warning.

use crate::batch::{BatchError, Counts};
use crate::messages::plural;
use crate::report::RecordView;
use crate::report::Verdict;
use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::Path;

/// One object's row.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// `batch.input`, or the scenario name for a line without one.
    pub input: String,
    /// `scenario`.
    pub scenario: String,
    /// `plan.status`, or `error`.
    pub status: String,
    /// `sim.verdict` (empty for an error).
    pub verdict: String,
    /// `sim.translation_mm`, when the check ran.
    pub translation_mm: Option<f64>,
    /// `sim.rotation_deg`, when the check ran.
    pub rotation_deg: Option<f64>,
    /// `sim.payload_margin`, when searched.
    pub payload_margin: Option<f64>,
    /// Each gravity direction and its verdict, `-Z hold +X slip`.
    pub directions: String,
    /// `expect.outcome`.
    pub expected: String,
    /// `expect.met`.
    pub met: Option<bool>,
    /// The object's wall time `[ms]`: `batch.wall_ms`, or (a line from `--json`) the plan's
    /// stage timings plus the check's wall time.
    pub wall_ms: f64,
    /// The error, for an object that could not be run.
    pub error: String,
    /// `sim.robust.hold_probability`, when the line has one (`[sim] samples` above 1).
    pub hold_probability: Option<f64>,
    /// `sim.robust.interval`'s lower bound, when the line has one.
    pub hold_lower_bound: Option<f64>,
}

impl Row {
    /// The verdict `verdict` names; `None` for an error, a check not run or a string that names
    /// no verdict (the row keeps the string as the line gave it).
    pub fn ran(&self) -> Option<Verdict> {
        Verdict::named(&self.verdict)
    }
}

/// Per gravity direction: how many grasps were checked under it and their verdicts.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct DirectionCount {
    /// Checked under this direction.
    pub checked: usize,
    /// Held.
    pub hold: usize,
    /// Slipped.
    pub slip: usize,
    /// Dropped.
    pub drop: usize,
}

/// The report on one results file.
#[derive(Debug, Clone, Default)]
pub struct Summary {
    /// The counts, as the batch summary line gives them.
    pub counts: Counts,
    /// Per gravity direction (a label such as `-Z (down)`), in label order.
    pub directions: BTreeMap<String, DirectionCount>,
    /// One row per line, in file order.
    pub rows: Vec<Row>,
    /// Things a reader should know (a partial last line, an input given twice).
    pub warnings: Vec<String>,
}

impl Summary {
    /// Reads a results file.
    ///
    /// # Errors
    /// [`BatchError::Io`] when it cannot be read; [`BatchError::NotARecord`] for a complete
    /// line that is not a run report or an error line (naming its line number).
    pub fn read(path: &Path) -> Result<Summary, BatchError> {
        // Line by line: the memory is the rows', not the file's (a 478 MB file, under the
        // 1 GiB cap, held whole and parsed into JSON trees, took 2.8 GB; issue 56).
        let limit = crate::files::MAX_RESULTS_BYTES;
        crate::files::check_regular(path, limit).map_err(|e| BatchError::io(path, e))?;
        let file = std::fs::File::open(path).map_err(|e| BatchError::io(path, e))?;
        let reader =
            std::io::BufReader::with_capacity(1 << 16, std::io::Read::take(file, limit + 1));
        Summary::from_reader(path, reader, limit)
    }

    /// [`Summary::read`] on the file's bytes (`path` names it in errors).
    ///
    /// # Errors
    /// As [`Summary::read`].
    pub fn parse(path: &Path, bytes: &[u8]) -> Result<Summary, BatchError> {
        Summary::from_reader(path, bytes, u64::MAX)
    }

    /// The summary of the lines `reader` gives, one at a time (at most `limit` bytes).
    fn from_reader(
        path: &Path,
        mut reader: impl std::io::BufRead,
        limit: u64,
    ) -> Result<Summary, BatchError> {
        let mut s = Summary::default();
        let mut seen: BTreeMap<String, usize> = BTreeMap::new();
        let mut line: Vec<u8> = Vec::new();
        let mut total = 0u64;
        for i in 0.. {
            line.clear();
            let n = reader
                .read_until(b'\n', &mut line)
                .map_err(|e| BatchError::io(path, e))?;
            total += n as u64;
            if total > limit {
                return Err(BatchError::io(
                    path,
                    std::io::Error::other(format!(
                        "more than the {limit} bytes a results file may have here"
                    )),
                ));
            }
            if n == 0 {
                break;
            }
            if line.last() != Some(&b'\n') {
                s.warnings.push(format!(
                    "skipped a partial last line ({n} bytes, no newline: a run interrupted while writing; `batch --resume` continues it)"
                ));
                break;
            }
            let line = &line[..line.len() - 1];
            if line.iter().all(u8::is_ascii_whitespace) {
                continue;
            }
            let bad = |why: String| BatchError::NotARecord {
                path: path.to_path_buf(),
                line: i + 1,
                why,
            };
            let v = view_of(line).map_err(bad)?;
            let row = row_of(&v).map_err(bad)?;
            *seen.entry(row.input.clone()).or_insert(0) += 1;
            s.count_directions(&v);
            s.counts.add(&v);
            s.rows.push(row);
        }
        let twice: Vec<String> = seen
            .iter()
            .filter(|(_, &n)| n > 1)
            .map(|(k, n)| format!("{k} ({n} times)"))
            .collect();
        if let Some(first) = twice.first() {
            s.warnings.push(format!(
                "{} given more than once (first: {first}); counted each time",
                plural(twice.len(), "input")
            ));
        }
        Ok(s)
    }

    /// Counts each gravity direction of the line `v` and its verdict.
    fn count_directions(&mut self, v: &RecordView) {
        for d in &v.sim.directions {
            let c = self
                .directions
                .entry(direction_label(&d.gravity))
                .or_default();
            c.checked += 1;
            match d.ran() {
                Some(Verdict::Hold) => c.hold += 1,
                Some(Verdict::Slip) => c.slip += 1,
                Some(Verdict::Drop) => c.drop += 1,
                None => {}
            }
        }
    }

    /// The report as text: `name` heads it; the `slowest` slowest objects are listed.
    pub fn to_text(&self, name: &str, slowest: usize) -> String {
        let c = &self.counts;
        let mut t = String::new();
        let pct = |n: usize| {
            if c.objects == 0 {
                0.0
            } else {
                100.0 * n as f64 / c.objects as f64
            }
        };
        let _ = writeln!(t, "{name}: {}", plural(c.objects, "object"));
        let _ = writeln!(
            t,
            "  planned       {} ({:.1} %), ungraspable {} ({:.1} %), errors {} ({:.1} %)",
            c.feasible,
            pct(c.feasible),
            c.ungraspable,
            pct(c.ungraspable),
            c.errors,
            pct(c.errors)
        );
        let checked = c.hold + c.slip + c.drop;
        let _ = writeln!(
            t,
            "  physics       {} checked: {} hold, {} slip, {} drop; {} not run",
            checked,
            c.hold,
            c.slip,
            c.drop,
            c.objects - c.errors - checked
        );
        if !self.directions.is_empty() {
            let _ = writeln!(t, "  held per gravity direction (aligned object frame):");
            for (label, d) in &self.directions {
                let _ = writeln!(
                    t,
                    "    {label:<10} {} of {} held ({} slip, {} drop)",
                    d.hold, d.checked, d.slip, d.drop
                );
            }
        }
        self.write_probabilities(&mut t);
        let _ = writeln!(
            t,
            "  expectations  {} met, {} not met, {} not judged",
            c.met, c.not_met, c.unjudged
        );
        // An empty sum of f64 is −0.0; `+ 0.0` makes it print as 0.0.
        let total_s: f64 = self.rows.iter().map(|r| r.wall_ms).sum::<f64>() / 1000.0 + 0.0;
        let _ = writeln!(
            t,
            "  time          {total_s:.1} s summed over objects ({:.3} s per object)",
            total_s / c.objects.max(1) as f64
        );
        self.write_slowest(&mut t, slowest);
        self.write_errors(&mut t);
        t
    }

    /// The hold probabilities of the lines that have one (`[sim] samples` above 1): their
    /// mean and spread, and how many main-check holds have a lower bound under 0.9.
    fn write_probabilities(&self, t: &mut String) {
        let sampled: Vec<&Row> = self
            .rows
            .iter()
            .filter(|r| r.hold_probability.is_some())
            .collect();
        if sampled.is_empty() {
            return;
        }
        let p: Vec<f64> = sampled.iter().filter_map(|r| r.hold_probability).collect();
        let mean = p.iter().sum::<f64>() / p.len() as f64;
        let count = |f: &dyn Fn(f64) -> bool| p.iter().filter(|x| f(**x)).count();
        let held = sampled.iter().filter(|r| r.ran() == Some(Verdict::Hold));
        let weak = held
            .clone()
            .filter(|r| r.hold_lower_bound.is_some_and(|lo| lo < 0.9))
            .count();
        let _ = writeln!(
            t,
            "  hold probability {} sampled: mean {mean:.3}; p = 1 {}, 0.5 <= p < 1 {}, 0 < p < 0.5 {}, p = 0 {}; {weak} of {} held in the main check have a 95 % lower bound under 0.9",
            sampled.len(),
            count(&|x| x == 1.0),
            count(&|x| (0.5..1.0).contains(&x)),
            count(&|x| x > 0.0 && x < 0.5),
            count(&|x| x == 0.0),
            held.count()
        );
    }

    /// The `slowest` slowest objects, slowest first, each with its outcome.
    fn write_slowest(&self, t: &mut String, slowest: usize) {
        let mut order: Vec<&Row> = self.rows.iter().collect();
        // Slowest first; equal times in file order (the sort is stable).
        order.sort_by(|a, b| b.wall_ms.total_cmp(&a.wall_ms));
        if slowest > 0 && !order.is_empty() {
            let _ = writeln!(t, "  slowest:");
            for r in order.iter().take(slowest) {
                let what = if r.error.is_empty() {
                    format!("{} {}", r.status, r.verdict)
                } else {
                    "error".to_string()
                };
                let _ = writeln!(
                    t,
                    "    {:>8.2} s  {}  ({what})",
                    r.wall_ms / 1000.0,
                    r.input
                );
            }
        }
    }

    /// The first ten errors, and how many more there are.
    fn write_errors(&self, t: &mut String) {
        let errors: Vec<&Row> = self.rows.iter().filter(|r| !r.error.is_empty()).collect();
        if !errors.is_empty() {
            let _ = writeln!(t, "  errors:");
            for r in errors.iter().take(10) {
                let _ = writeln!(t, "    {}: {}", r.input, r.error);
            }
            if errors.len() > 10 {
                let _ = writeln!(t, "    ... and {} more (see the CSV)", errors.len() - 10);
            }
        }
    }

    /// One row per object, in file order, with a header.
    ///
    /// With hold probabilities on any line, two columns more at the end:
    /// `hold_probability,hold_lower_bound`.
    pub fn to_csv(&self) -> String {
        let sampled = self.rows.iter().any(|r| r.hold_probability.is_some());
        let mut t = String::from(
            "input,scenario,status,verdict,translation_mm,rotation_deg,payload_margin,directions,expected,met,wall_ms,error",
        );
        t.push_str(if sampled {
            ",hold_probability,hold_lower_bound\n"
        } else {
            "\n"
        });
        let num = |x: Option<f64>| x.map_or(String::new(), |v| format!("{v}"));
        for r in &self.rows {
            let mut fields = vec![
                csv_field(&r.input),
                csv_field(&r.scenario),
                csv_field(&r.status),
                csv_field(&r.verdict),
                num(r.translation_mm),
                num(r.rotation_deg),
                num(r.payload_margin),
                csv_field(&r.directions),
                csv_field(&r.expected),
                r.met.map_or(String::new(), |m| m.to_string()),
                format!("{:.3}", r.wall_ms),
                csv_field(&r.error),
            ];
            if sampled {
                fields.push(num(r.hold_probability));
                fields.push(num(r.hold_lower_bound));
            }
            t.push_str(&fields.join(","));
            t.push('\n');
        }
        t
    }
}

/// A field quoted when it holds a comma, a quote or a line break (RFC 4180).
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// `-Z (down)` for gravity along an axis (the aligned object frame, the thesis's weight
/// direction −Z), the rounded vector otherwise.
fn direction_label(v: &[f64]) -> String {
    if v.len() != 3 {
        return "?".to_string();
    }
    for (i, axis) in ["X", "Y", "Z"].iter().enumerate() {
        if (v[i].abs() - 1.0).abs() < 1e-6 {
            let sign = if v[i] < 0.0 { "-" } else { "+" };
            let down = if i == 2 && v[i] < 0.0 { " (down)" } else { "" };
            return format!("{sign}{axis}{down}");
        }
    }
    format!("({:.3}, {:.3}, {:.3})", v[0], v[1], v[2])
}

/// The view of one complete line (without its newline), or why it is not a JSON object.
fn view_of(line: &[u8]) -> Result<RecordView, String> {
    let text = std::str::from_utf8(line).map_err(|_| "not UTF-8".to_string())?;
    // The view straight from the text (no JSON tree of the whole line); where that fails, the
    // tree says why.
    match serde_json::from_str::<RecordView>(text) {
        Ok(v) if text.trim_start().starts_with('{') => Ok(v),
        _ => {
            let v: serde_json::Value =
                serde_json::from_str(text).map_err(|e| format!("not JSON ({e})"))?;
            if !v.is_object() {
                return Err("not a JSON object".to_string());
            }
            Ok(RecordView::of(&v))
        }
    }
}

/// The row of one line.
fn row_of(v: &RecordView) -> Result<Row, String> {
    let scenario = v
        .scenario
        .clone()
        .ok_or("no `scenario` (not a run report from `batch` or `--json`)")?;
    let input = v.batch.input.clone().unwrap_or_else(|| scenario.clone());
    if let Some(e) = &v.error {
        return Ok(Row {
            input,
            scenario,
            status: "error".to_string(),
            verdict: String::new(),
            translation_mm: None,
            rotation_deg: None,
            payload_margin: None,
            directions: String::new(),
            expected: String::new(),
            met: None,
            wall_ms: v.batch.wall_ms.unwrap_or(0.0),
            error: e.text().to_string(),
            hold_probability: None,
            hold_lower_bound: None,
        });
    }
    let status = v
        .plan
        .status
        .clone()
        .ok_or("no `plan.status` (not a run report)")?;
    let sim = &v.sim;
    let directions: Vec<String> = sim
        .directions
        .iter()
        .map(|d| {
            let label = direction_label(&d.gravity);
            let label = label.trim_end_matches(" (down)");
            format!("{label} {}", d.verdict.as_deref().unwrap_or("?"))
        })
        .collect();
    let wall_ms = v.batch.wall_ms.unwrap_or_else(|| {
        let plan: f64 = v.plan.timings_ms.as_ref().map_or(0.0, |t| t.iter().sum());
        plan + sim.wall_ms.unwrap_or(0.0)
    });
    Ok(Row {
        input,
        scenario,
        status,
        verdict: sim.verdict.clone().unwrap_or_default(),
        translation_mm: sim.translation_mm,
        rotation_deg: sim.rotation_deg,
        payload_margin: sim.payload_margin,
        directions: directions.join(" "),
        expected: v.expect.outcome.clone().unwrap_or_default(),
        met: v.expect.met,
        wall_ms,
        error: String::new(),
        hold_probability: sim.robust.hold_probability,
        hold_lower_bound: sim.robust.lower_bound(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const HOLD: &str = r#"{"scenario":"a","plan":{"status":"feasible"},"sim":{"verdict":"hold","translation_mm":0.5,"rotation_deg":0.25,"directions":[{"gravity":[0.0,0.0,-1.0],"verdict":"hold"},{"gravity":[1.0,0.0,0.0],"verdict":"slip"}]},"expect":{"outcome":"hold","met":true},"batch":{"input":"d/a.toml","input_hash":"sha256:0","wall_ms":1500.0}}"#;
    const UNGRASPABLE: &str = r#"{"scenario":"b","plan":{"status":"ungraspable","timings_ms":{"load":1.0,"search":2.5}},"sim":{"verdict":"not_run"},"expect":{"outcome":"none","met":null}}"#;
    const ERROR: &str = r#"{"scenario":"d/c, \"odd\".stl","error":"timed out","batch":{"input":"d/c, \"odd\".stl","input_hash":"sha256:1","wall_ms":2000.0}}"#;

    #[test]
    fn counts_directions_slowest_and_csv() {
        let text = format!("{HOLD}\n{UNGRASPABLE}\n\n{ERROR}\n{{\"scen");
        let s = Summary::parse(Path::new("r.jsonl"), text.as_bytes()).unwrap();
        assert_eq!(s.counts.objects, 3);
        assert_eq!(
            (
                s.counts.feasible,
                s.counts.ungraspable,
                s.counts.errors,
                s.counts.hold
            ),
            (1, 1, 1, 1)
        );
        assert_eq!(s.directions["-Z (down)"].hold, 1);
        assert_eq!(s.directions["+X"].slip, 1);
        assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
        assert!(s.warnings[0].contains("partial last line"));
        assert_eq!(s.rows[1].wall_ms, 3.5);
        let t = s.to_text("r.jsonl", 2);
        assert!(t.contains("r.jsonl: 3 objects"), "{t}");
        assert!(t.contains("-Z (down)  1 of 1 held"), "{t}");
        let slow: Vec<&str> = t
            .lines()
            .skip_while(|l| !l.contains("slowest"))
            .skip(1)
            .take(2)
            .collect();
        assert!(
            slow[0].contains("2.00 s") && slow[1].contains("1.50 s  d/a.toml"),
            "{t}"
        );
        let csv = s.to_csv();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 4);
        assert_eq!(
            lines[1],
            "d/a.toml,a,feasible,hold,0.5,0.25,,-Z hold +X slip,hold,true,1500.000,"
        );
        assert!(
            lines[3].starts_with("\"d/c, \"\"odd\"\".stl\","),
            "{}",
            lines[3]
        );
    }

    #[test]
    fn hold_probabilities_are_summed_up_and_written_when_present() {
        let sampled = HOLD.replace(
            r#""directions":"#,
            r#""robust":{"samples":16,"hold_probability":0.875,"interval":[0.64,0.965]},"directions":"#,
        );
        let text = format!("{sampled}\n{UNGRASPABLE}\n");
        let s = Summary::parse(Path::new("r.jsonl"), text.as_bytes()).unwrap();
        assert_eq!(s.rows[0].hold_probability, Some(0.875));
        assert_eq!(s.rows[0].hold_lower_bound, Some(0.64));
        let t = s.to_text("r.jsonl", 0);
        assert!(
            t.contains("hold probability 1 sampled: mean 0.875; p = 1 0, 0.5 <= p < 1 1")
                && t.contains("1 of 1 held in the main check have a 95 % lower bound under 0.9"),
            "{t}"
        );
        let csv = s.to_csv();
        let lines: Vec<&str> = csv.lines().collect();
        assert!(lines[0].ends_with(",error,hold_probability,hold_lower_bound"));
        assert!(lines[1].ends_with(",1500.000,,0.875,0.64"), "{}", lines[1]);
        assert!(lines[2].ends_with(",,"), "{}", lines[2]);
        // Without probabilities the CSV keeps its columns.
        let plain = Summary::parse(Path::new("r.jsonl"), HOLD.as_bytes()).unwrap();
        assert!(plain
            .to_csv()
            .lines()
            .next()
            .unwrap()
            .ends_with(",wall_ms,error"));
        assert!(!plain.to_text("r", 0).contains("hold probability"));
    }

    #[test]
    fn bad_lines_name_the_file_and_line() {
        for (text, why) in [
            (
                "{\"scenario\":\"a\",\"plan\":{\"status\":\"feasible\"}}\nnot json\n",
                "line 2 is not a batch record: not JSON",
            ),
            ("[1]\n", "line 1 is not a batch record: not a JSON object"),
            ("{\"x\":1}\n", "no `scenario`"),
            ("{\"scenario\":\"a\"}\n", "no `plan.status`"),
        ] {
            let e = Summary::parse(Path::new("r.jsonl"), text.as_bytes())
                .unwrap_err()
                .to_string();
            assert!(e.starts_with("r.jsonl: ") && e.contains(why), "{e}");
        }
    }
}
