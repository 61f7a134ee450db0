//! The repository speaks for itself (issue 59): no file says how the project was made, every
//! relative link and anchor of the Markdown files resolves, every study opens as
//! docs/studies/README.md says and is indexed there, the reference docs and the README stay
//! short, and the README's headline figures are the ones the generated tables hold.
//!
//! The files are those git tracks (`git ls-files`), or, without git, every file under the root
//! but `target/`, `.git/`, `out/`, `tune/` and the paths `.gitignore` names. The patterns are
//! built from pieces, so this file does not match them itself.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Mesh and image data: no words in them.
const DATA: &[&str] = &["stl", "obj", "ply", "png", "glb", "svg"];

/// The repository's files, relative to the root, in order.
fn files() -> Vec<PathBuf> {
    let root = crate::root();
    let listed = std::process::Command::new("git")
        .args(["ls-files", "-z"])
        .current_dir(&root)
        .output();
    if let Ok(out) = listed {
        if out.status.success() {
            return out
                .stdout
                .split(|&b| b == 0)
                .filter(|p| !p.is_empty())
                .map(|p| PathBuf::from(String::from_utf8_lossy(p).into_owned()))
                .filter(|p| root.join(p).is_file())
                .collect();
        }
    }
    let ignored: BTreeSet<PathBuf> = std::fs::read_to_string(root.join(".gitignore"))
        .unwrap_or_default()
        .lines()
        .filter_map(|l| l.strip_prefix('/'))
        .map(PathBuf::from)
        .collect();
    let mut found = Vec::new();
    walk(&root, Path::new(""), &ignored, &mut found);
    found.sort();
    found
}

fn walk(root: &Path, rel: &Path, ignored: &BTreeSet<PathBuf>, found: &mut Vec<PathBuf>) {
    let skip = ["target", ".git", "out", "tune", "corpus", "artifacts"];
    for entry in std::fs::read_dir(root.join(rel)).unwrap().flatten() {
        let name = entry.file_name();
        let path = rel.join(&name);
        if skip.iter().any(|s| name == *s) || ignored.contains(&path) {
            continue;
        }
        if entry.path().is_dir() {
            walk(root, &path, ignored, found);
        } else {
            found.push(path);
        }
    }
}

/// The file's text, or None for data and binary files.
fn text(path: &Path) -> Option<String> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if DATA.contains(&ext.to_ascii_lowercase().as_str()) {
        return None;
    }
    let bytes = std::fs::read(crate::root().join(path)).ok()?;
    if bytes.contains(&0) {
        return None;
    }
    String::from_utf8(bytes).ok()
}

fn is_word_char(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// Where `word` (lower case) stands as a whole word in `line`, any case, with an optional
/// plural `s`.
fn has_word(line: &str, word: &str) -> bool {
    let lower = line.to_lowercase();
    let mut from = 0;
    while let Some(i) = lower[from..].find(word) {
        let start = from + i;
        let end = start + word.len();
        let before = lower[..start].chars().next_back();
        let mut after = lower[end..].chars();
        let next = match after.clone().next() {
            Some('s') => {
                after.next();
                after.next()
            }
            c => c,
        };
        if !before.is_some_and(is_word_char) && !next.is_some_and(is_word_char) {
            return true;
        }
        from = end;
    }
    false
}

/// A whole word made of `letter` and then `min`–`max` digits, optionally followed by `tail`
/// (a helper's name is a letter and a number; a branch named after one adds a dash).
fn has_letter_number(line: &str, letter: char, min: usize, max: usize, tail: &str) -> bool {
    let chars: Vec<char> = line.chars().collect();
    for i in 0..chars.len() {
        if chars[i] != letter || (i > 0 && is_word_char(chars[i - 1])) {
            continue;
        }
        let digits = chars[i + 1..]
            .iter()
            .take_while(|c| c.is_ascii_digit())
            .count();
        if digits < min || digits > max {
            continue;
        }
        let rest: String = chars[i + 1 + digits..].iter().collect();
        if tail.is_empty() {
            if !rest.chars().next().is_some_and(is_word_char) {
                return true;
            }
        } else if rest.starts_with(tail) && rest[tail.len()..].starts_with(char::is_alphanumeric) {
            return true;
        }
    }
    false
}

/// What a line says of how the project was made, if anything.
fn provenance(line: &str) -> Option<&'static str> {
    let lower = line.to_lowercase();
    let worker = ["ses", "sion"].concat();
    let helper = ["hel", "per"].concat();
    let lead = ["the ", "lead"].concat();
    if has_word(line, &worker) {
        return Some("the name of a sitting of work");
    }
    for folder in ["tmp", "work"] {
        if lower.contains(&format!("/{folder}/")) {
            return Some("a machine's work folder");
        }
    }
    if has_letter_number(line, 'h', 2, 3, "") {
        return Some("a helper's initial and number");
    }
    if has_letter_number(line, 's', 2, 2, "-") {
        return Some("a work branch's name");
    }
    let counted = [
        "two", "three", "four", "five", "six", "seven", "eight", "other",
    ];
    if counted
        .iter()
        .any(|n| has_word(&lower, &format!("{n} {helper}")))
    {
        return Some("the helpers who did the work");
    }
    if let Some(i) = lower.find(&lead) {
        let rest = &lower[i + lead.len()..];
        if !rest.starts_with(char::is_alphanumeric) && !rest.starts_with(" of") {
            return Some("the lead of the work");
        }
    }
    None
}

#[test]
fn the_checks_patterns_find_what_they_are_for() {
    let w = ["ses", "sion"].concat();
    for line in [
        format!("measured in {w} 46"),
        format!("the {w}s before"),
        format!("{}'s rule", ["h", "33"].concat()),
        format!("/{}/bench.json", "tmp"),
        format!("branch {}", ["s4", "0-32"].concat()),
        format!(
            "six {}s and {} on 2 cores",
            ["hel", "per"].concat(),
            ["the ", "lead"].concat()
        ),
    ] {
        assert!(provenance(&line).is_some(), "not found in {line:?}");
    }
    for line in [
        "the possession of the object",
        "<h2>Figures</h2>, h1 and h2 as variables",
        "the lead of rapier's velocity-first update",
        "small 2D helpers for the positioning stages",
        "frames written in s10 steps",
    ] {
        assert_eq!(provenance(line), None, "{line:?}");
    }
}

#[test]
fn no_file_says_how_the_project_was_made() {
    let mut found = Vec::new();
    for path in files() {
        let Some(text) = text(&path) else { continue };
        for (n, line) in text.lines().enumerate() {
            if let Some(what) = provenance(line) {
                found.push(format!(
                    "{}:{}: {what}: {}",
                    path.display(),
                    n + 1,
                    line.trim()
                ));
            }
        }
    }
    assert!(
        found.is_empty(),
        "{} lines say how the project was made (a date, a commit or an issue number says it \
         to a reader):\n{}",
        found.len(),
        found.join("\n")
    );
}

/// The line with its inline code spans blanked.
fn without_code_spans(line: &str) -> String {
    let mut out = String::new();
    let mut in_code = false;
    for c in line.chars() {
        if c == '`' {
            in_code = !in_code;
            out.push(' ');
        } else {
            out.push(if in_code { ' ' } else { c });
        }
    }
    out
}

/// The Markdown lines outside fenced and indented code blocks, with their numbers.
fn prose(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut fenced = false;
    let mut previous_blank = true;
    let mut indented = false;
    for (n, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        let blank = line.trim().is_empty();
        if !fenced && line.starts_with("    ") && (previous_blank || indented) {
            let item = line.trim_start();
            let is_list = item.starts_with("- ") || item.starts_with("* ");
            indented = !is_list;
        } else if !blank {
            indented = false;
        }
        previous_blank = blank;
        if !fenced && !indented {
            out.push((n + 1, without_code_spans(line)));
        }
    }
    out
}

/// GitHub's anchor of a heading.
fn slug(heading: &str) -> String {
    let mut text = String::new();
    let mut rest = heading;
    // Links in headings keep their text only.
    while let Some(i) = rest.find("](") {
        let Some(j) = rest[i..].find(')') else { break };
        text.push_str(&rest[..i]);
        rest = &rest[i + j + 1..];
    }
    text.push_str(rest);
    text.to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == ' ' || *c == '-' || *c == '_')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The anchors of a Markdown file's headings.
fn anchors(text: &str) -> BTreeSet<String> {
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    let mut out = BTreeSet::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        let level = line.chars().take_while(|&c| c == '#').count();
        if fenced || level == 0 || level > 6 || !line[level..].starts_with(' ') {
            continue;
        }
        let base = slug(line[level..].trim());
        let k = seen.entry(base.clone()).or_insert(0);
        out.insert(if *k == 0 {
            base.clone()
        } else {
            format!("{base}-{k}")
        });
        *k += 1;
    }
    out
}

/// The targets of the inline links and images of a line.
fn link_targets(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = line;
    while let Some(i) = rest.find("](") {
        let after = &rest[i + 2..];
        let Some(j) = after.find(')') else { break };
        let target = after[..j].split_whitespace().next().unwrap_or("");
        if !target.is_empty() {
            out.push(target.to_string());
        }
        rest = &after[j..];
    }
    out
}

#[test]
fn every_relative_link_and_anchor_in_the_markdown_resolves() {
    let root = crate::root();
    let mut broken = Vec::new();
    let mut cache: BTreeMap<PathBuf, BTreeSet<String>> = BTreeMap::new();
    let markdown: Vec<PathBuf> = files()
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    for path in &markdown {
        let text = std::fs::read_to_string(root.join(path)).unwrap();
        let dir = path.parent().unwrap_or(Path::new(""));
        for (n, line) in prose(&text) {
            for target in link_targets(&line) {
                if target.contains("://") || target.starts_with("mailto:") {
                    continue;
                }
                let (file, anchor) = match target.split_once('#') {
                    Some((f, a)) => (f, Some(a)),
                    None => (target.as_str(), None),
                };
                let resolved = if file.is_empty() {
                    path.clone()
                } else {
                    dir.join(file)
                };
                let full = root.join(&resolved);
                if !full.exists() {
                    broken.push(format!("{}:{n}: {target}: no such file", path.display()));
                    continue;
                }
                let Some(anchor) = anchor else { continue };
                if full.extension().is_some_and(|e| e == "md") {
                    let known = cache.entry(full.clone()).or_insert_with(|| {
                        anchors(&std::fs::read_to_string(&full).unwrap_or_default())
                    });
                    if !known.contains(anchor) {
                        broken.push(format!("{}:{n}: {target}: no such heading", path.display()));
                    }
                }
            }
        }
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

/// A reference doc says what is, briefly, and links to the studies for the measurements and
/// the histories (issue 59): at most 400 lines each, the README at most 200.
#[test]
fn reference_docs_and_the_readme_stay_short() {
    let root = crate::root();
    let mut long = Vec::new();
    for path in files() {
        let limit = if path == Path::new("README.md") {
            200
        } else if path.parent() == Some(Path::new("docs"))
            && path.extension().is_some_and(|e| e == "md")
        {
            400
        } else {
            continue;
        };
        let lines = std::fs::read_to_string(root.join(&path))
            .unwrap()
            .lines()
            .count();
        if lines > limit {
            long.push(format!("{}: {lines} lines, over {limit}", path.display()));
        }
    }
    assert!(long.is_empty(), "too long:\n{}", long.join("\n"));
}

#[test]
fn the_link_checks_slugs_are_githubs() {
    assert_eq!(
        slug("The report folder: `--report DIR`"),
        "the-report-folder---report-dir"
    );
    assert_eq!(
        slug("Limits on inputs and outputs (issue 32)"),
        "limits-on-inputs-and-outputs-issue-32"
    );
    assert_eq!(
        slug("Stages 1–3 against the thesis"),
        "stages-13-against-the-thesis"
    );
    let a = anchors("# A\n## B\n```\n# not a heading\n```\n## B\n");
    assert!(a.contains("a") && a.contains("b") && a.contains("b-1") && a.len() == 3);
}

#[test]
fn every_study_opens_with_its_question_command_commit_and_answer_and_is_indexed() {
    let dir = crate::root().join("docs/studies");
    let index = std::fs::read_to_string(dir.join("README.md")).unwrap();
    let mut studies = 0;
    for entry in std::fs::read_dir(&dir).unwrap().flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        if name == "README.md" {
            continue;
        }
        studies += 1;
        let b = name.as_bytes();
        let dated = b.len() > 14
            && b[..10].iter().enumerate().all(|(i, c)| {
                if i == 4 || i == 7 {
                    *c == b'-'
                } else {
                    c.is_ascii_digit()
                }
            })
            && b[10] == b'-'
            && name.ends_with(".md")
            && name[11..name.len() - 3]
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-');
        assert!(dated, "{name}: not named YYYY-MM-DD-topic.md");
        let text = std::fs::read_to_string(entry.path()).unwrap();
        assert!(text.starts_with("# "), "{name}: no title");
        let head: Vec<&str> = text.lines().take(30).collect();
        let mut at = 0;
        for label in ["Question", "Command", "Commit", "Answer"] {
            let mark = format!("- **{label}.**");
            let Some(i) = head[at..].iter().position(|l| l.starts_with(&mark)) else {
                panic!("{name}: no {mark} line (in this order) at its opening");
            };
            at += i + 1;
        }
        assert!(
            index.contains(&format!("]({name})")),
            "{name}: not in docs/studies/README.md"
        );
    }
    assert!(studies > 0, "no studies in docs/studies");
}

/// The text of the block `script` writes in `doc` (between its BEGIN and the next END line).
fn generated(doc: &str, script: &str) -> String {
    let path = crate::root().join(doc);
    let text = std::fs::read_to_string(&path).unwrap();
    let begin = format!("<!-- BEGIN GENERATED: {script} -->");
    let start = text
        .find(&begin)
        .unwrap_or_else(|| panic!("{doc}: no block of {script}"))
        + begin.len();
    let end = start
        + text[start..]
            .find("<!-- END GENERATED -->")
            .unwrap_or_else(|| panic!("{doc}: the block of {script} does not end"));
    text[start..end].to_string()
}

/// The KEY=VALUE pairs of a block's headline line (scripts/docblock.py).
fn headline(doc: &str, script: &str) -> BTreeMap<String, String> {
    let block = generated(doc, script);
    let line = block
        .lines()
        .find(|l| l.starts_with("<!-- headline:"))
        .unwrap_or_else(|| panic!("{doc}: the block of {script} has no headline line"));
    line["<!-- headline:".len()..line.len() - "-->".len()]
        .split_whitespace()
        .filter_map(|p| p.split_once('='))
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect()
}

/// The README's headline block as scripts/headline.py writes it from the same sources.
fn expected_headline() -> String {
    let t = headline("docs/USAGE.md", "scripts/thesis_table.py");
    let p = headline("BENCHMARKS.md", "scripts/plan_bench.py");
    let s = headline("BENCHMARKS.md", "scripts/speed_ratios.py");
    let m = headline("docs/MUJOCO.md", "scripts/compare_engines.py");
    let real = generated("docs/REAL_OBJECTS.md", "scripts/real_objects_eval.py");
    let summary = real
        .lines()
        .find(|l| l.starts_with("**Summary**"))
        .expect("REAL_OBJECTS.md's generated block has no **Summary** line");
    let numbers = |s: &str| -> Vec<String> {
        s.split(|c: char| !c.is_ascii_digit())
            .filter(|n| !n.is_empty())
            .map(str::to_string)
            .collect()
    };
    // The set's figures come first; MuJoCo's after "MuJoCo replays" (replays, verdicts agreed).
    let (set, mujoco) = summary
        .split_once("MuJoCo replays")
        .expect("REAL_OBJECTS.md's Summary line names no MuJoCo replay");
    let (r, q) = (numbers(set), numbers(mujoco));
    let (graspable, planned, down, six) = (&r[0], &r[1], &r[3], &r[5]);
    let (replayed, agree) = (&q[0], &q[1]);
    let lines = [
        format!(
            "- **The thesis.** {} of the {} thesis scenarios match the thesis's Grasp Parameter \
             Set within its tolerances ({}); the others differ for a stated reason \
             ([docs/USAGE.md](docs/USAGE.md#the-grasp-parameter-sets-against-the-thesis)).",
            t["matching"],
            t["scenarios"],
            t["names"].replace(',', ", ")
        ),
        format!(
            "- **Real objects.** Of {graspable} real objects labelled graspable, {planned} get a \
             grasp; {down} hold with gravity down and {six} in all six directions \
             ([docs/REAL_OBJECTS.md](docs/REAL_OBJECTS.md#the-table))."
        ),
        format!(
            "- **Another engine.** MuJoCo replays the checked grasps and agrees with rapier on \
             {} of {} bundled and tuning-set grasps and on {agree} of {replayed} real-object \
             grasps ([docs/MUJOCO.md](docs/MUJOCO.md#agreement)).",
            m["agree"], m["compared"]
        ),
        format!(
            "- **Planning time.** {} of {} real and hard meshes plan within 5 s: median {} s, \
             95th percentile {} s, the slowest ({}) {} s, in a run at load average {} on 2 \
             cores ([BENCHMARKS.md](BENCHMARKS.md#planning-time-on-any-mesh)).",
            p["within_5s"],
            p["objects"],
            p["median_s"],
            p["p95_s"],
            p["slowest"],
            p["max_s"],
            p["load"]
        ),
        format!(
            "- **The check's speed.** The D40 cylinder's check takes {} of the time MuJoCo's \
             replay of the same scene (at its 0.025 ms step) takes with gravity down ({} ms) and \
             {} in six directions; \
             a batch of the real-object set runs {} six-direction checks a second on 2 cores at \
             load average {} ([BENCHMARKS.md](BENCHMARKS.md#physics-check)).",
            s["down_ratio"], s["down_ms"], s["six_ratio"], s["checks_per_s"], s["load"]
        ),
    ];
    lines.join("\n")
}

#[test]
fn the_readmes_headline_figures_are_the_generated_tables() {
    let have = generated("README.md", "scripts/headline.py");
    let want = expected_headline();
    assert_eq!(
        have.trim_matches('\n'),
        want,
        "README.md's headline block is not what the generated tables say; run \
         python3 scripts/headline.py"
    );
}
