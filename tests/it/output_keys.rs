//! The JSON's keys against docs/OUTPUT.md's "Every key" (issue 59): runs of the main command and
//! of `batch` that between them write every optional part (a grasp and its candidates, six
//! directions, samples, the payload, quality, an ungraspable object, a stopped search, a palm
//! stand-off, a replay, a refinement, `closing_decides`, an error line) give exactly the keys the
//! list documents, each key a path of object keys joined with '.', arrays' elements merged.

use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};

/// Keys the list documents that none of these runs writes, and why.
const NOT_WRITTEN_HERE: &[(&str, &str)] = &[(
    "quality.linf_note",
    "written only when the L-infinity epsilon search does not finish",
)];

/// The documented key paths: the "Every key" block of docs/OUTPUT.md, with its `= X` aliases
/// expanded and `[]` dropped.
fn documented() -> BTreeSet<String> {
    let text = std::fs::read_to_string(crate::root().join("docs/OUTPUT.md")).unwrap();
    let after = text
        .split_once("\n### Every key\n")
        .expect("docs/OUTPUT.md: no \"### Every key\" section")
        .1;
    let block = after
        .split_once("```text\n")
        .and_then(|(_, rest)| rest.split_once("\n```"))
        .expect("docs/OUTPUT.md: no ```text block under \"Every key\"")
        .0;
    let mut children: Vec<(String, Vec<String>)> = Vec::new();
    for line in block.lines().filter(|l| !l.trim().is_empty()) {
        if line.starts_with(char::is_whitespace) {
            let last = children.last_mut().expect("a continuation line first");
            last.1.extend(line.split_whitespace().map(str::to_string));
        } else {
            let (parent, rest) = line
                .split_once(':')
                .unwrap_or_else(|| panic!("docs/OUTPUT.md: `{line}` is not `parent: keys`"));
            let parent = parent.replace("[]", "");
            let parent = if parent == "." { String::new() } else { parent };
            children.push((
                parent,
                rest.split_whitespace().map(str::to_string).collect(),
            ));
        }
    }
    let join = |parent: &str, key: &str| {
        if parent.is_empty() {
            key.to_string()
        } else {
            format!("{parent}.{key}")
        }
    };
    let mut keys = BTreeSet::new();
    let mut aliases = Vec::new();
    for (parent, words) in &children {
        match words.as_slice() {
            [eq, target] if eq == "=" => aliases.push((parent.clone(), target.replace("[]", ""))),
            _ => keys.extend(words.iter().map(|w| join(parent, w))),
        }
    }
    // `P: = X`: every key under X is also under P (to a fixed point: aliases of aliases).
    loop {
        let mut added = Vec::new();
        for (p, x) in &aliases {
            for k in &keys {
                if let Some(rest) = k.strip_prefix(&format!("{x}.")) {
                    let new = format!("{p}.{rest}");
                    if !keys.contains(&new) {
                        added.push(new);
                    }
                }
            }
        }
        if added.is_empty() {
            break;
        }
        keys.extend(added);
    }
    keys
}

/// Every key path of `v` under `prefix`. An object whose keys the list gives as one `<name>`
/// (`wildcards`: its path and that word) has each key written as the word.
fn key_paths(
    v: &Value,
    prefix: &str,
    wildcards: &BTreeMap<String, String>,
    out: &mut BTreeSet<String>,
) {
    match v {
        Value::Object(o) => {
            for (k, x) in o {
                let k = wildcards.get(prefix).unwrap_or(k);
                let path = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                out.insert(path.clone());
                key_paths(x, &path, wildcards, out);
            }
        }
        Value::Array(a) => a.iter().for_each(|x| key_paths(x, prefix, wildcards, out)),
        _ => {}
    }
}

/// A scenario file in `dir` with `body`, its mesh (and hand) paths made absolute.
fn scenario(dir: &std::path::Path, name: &str, body: &str) -> String {
    let root = crate::root();
    let text =
        format!("name = \"{name}\"\n{body}").replace("ROOT/", &format!("{}/", root.display()));
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

#[test]
fn the_json_keys_are_the_ones_output_md_lists() {
    let doc = documented();
    let wildcards: BTreeMap<String, String> = doc
        .iter()
        .filter_map(|k| {
            let (parent, last) = k.rsplit_once('.')?;
            (last.starts_with('<') && last.ends_with('>'))
                .then(|| (parent.to_string(), last.to_string()))
        })
        .collect();

    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // The chapter 4 object's first candidates are rejected: a budget of 2 stops its search.
    let budget = scenario(
        d,
        "budget",
        "[object]\nmesh = \"ROOT/assets/objects/chapter4.stl\"\n[planner]\ncandidate_budget = 2\n",
    );
    // A slippery heavy D40 drops: samples fail (first_failure), every candidate is sampled, the
    // first sample replayed, the plan refined by the contact.
    let robust = scenario(
        d,
        "robust",
        "[object]\nmesh = \"ROOT/assets/objects/cylinder_d40.stl\"\nmass_kg = 2.0\nfriction = 0.05\n\
         [planner]\nvertical_deviation_deg = 2.0\n\
         [sim]\nsamples = 2\nchoose = \"robust\"\nreplay_sample = 0\nmax_checked = 2\nrefine_contacts = true\n",
    );
    // The SDH-2 on the cup from 20° open pushes it off the plan: under closing_decides later
    // candidates are reported `not_run` with their reason.
    let decides = scenario(
        d,
        "decides",
        "[object]\nmesh = \"ROOT/assets/objects/cup.stl\"\n[hand]\nurdf = \"ROOT/assets/hands/sdh2.urdf\"\n\
         [planner]\nheight_step_mm = 3.0\n[sim]\nclosing_decides = true\norder_by_closing = 0\n",
    );
    // The same, searched in the order its closings give (`order_by_closing`, the default): the
    // first candidate's closing leaves its plan, so the picks carry `closing_order`.
    let ordered = scenario(
        d,
        "ordered",
        "[object]\nmesh = \"ROOT/assets/objects/cup.stl\"\n[hand]\nurdf = \"ROOT/assets/hands/sdh2.urdf\"\n\
         [planner]\nheight_step_mm = 3.0\n[sim]\nmax_checked = 1\n",
    );
    let missing = d.join("missing.stl").display().to_string();
    let runs: Vec<(Vec<&str>, i32)> = vec![
        (
            vec![
                "--json",
                "--payload",
                "--quality",
                "--samples",
                "2",
                "--gravity",
                "six",
                "--candidates",
                "2",
                "scenarios/cylinder_d40.toml",
            ],
            0,
        ),
        (
            vec![
                "--json",
                "--payload",
                "--quality",
                "scenarios/cup_inverted.toml",
                "scenarios/sim_open_fingers.toml",
            ],
            0,
        ),
        (
            vec![
                "batch",
                "--no-sim",
                "scenarios/cylinder_d10.toml",
                "scenarios/hands/sdh2_cup.toml",
                &budget,
                &missing,
            ],
            2,
        ),
        (vec!["--json", &robust, &decides], 0),
        (vec!["--json", &ordered], 0),
    ];
    let mut written = BTreeSet::new();
    for (args, status) in &runs {
        let out = crate::grasp_sim().args(args).output().unwrap();
        assert_eq!(
            out.status.code(),
            Some(*status),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        for line in String::from_utf8(out.stdout).unwrap().lines() {
            let v: Value = serde_json::from_str(line).unwrap();
            key_paths(&v, "", &wildcards, &mut written);
        }
    }

    let allowed: BTreeSet<String> = NOT_WRITTEN_HERE
        .iter()
        .map(|(k, _)| k.to_string())
        .collect();
    let undocumented: Vec<&String> = written.difference(&doc).collect();
    let unwritten: Vec<&String> = doc
        .difference(&written)
        .filter(|k| !allowed.contains(*k))
        .collect();
    let stale_allowance: Vec<&String> = allowed
        .iter()
        .filter(|k| written.contains(*k) || !doc.contains(*k))
        .collect();
    assert!(
        undocumented.is_empty() && unwritten.is_empty() && stale_allowance.is_empty(),
        "the JSON and docs/OUTPUT.md's \"Every key\" disagree:\n\
         written but not listed: {undocumented:?}\n\
         listed but not written: {unwritten:?}\n\
         allowed as not written, but written or not listed: {stale_allowance:?}"
    );
}
