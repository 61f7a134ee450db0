//! The `grasp-sim` binary: parse flags, run, map the result to an exit code.

mod cli;

use anyhow::Context;
use clap::Parser;
use grasp_sim::{
    run,
    scenario::{GravityMode, Scenario},
    RunOptions,
};
use std::io::Write;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = match cli::Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    match real_main(cli) {
        Ok(code) => ExitCode::from(code),
        // The reader went away (`grasp-sim --json ... | head`): stop quietly, as ripgrep does;
        // that is not bad input.
        Err(e)
            if e.chain().any(|c| {
                c.downcast_ref::<std::io::Error>()
                    .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
            }) =>
        {
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("grasp-sim: error: {}", format!("{e:#}").replace('\n', " "));
            ExitCode::from(2)
        }
    }
}

fn real_main(cli: cli::Cli) -> anyhow::Result<u8> {
    match cli.command {
        Some(cli::Command::GenAssets { out, hard: true }) => {
            return gen_hard_assets(&out).map(|()| 0)
        }
        Some(cli::Command::GenAssets { out, hard: false }) => return gen_assets(&out).map(|()| 0),
        Some(cli::Command::Batch(args)) => return batch(&args),
        Some(cli::Command::BatchWorker {
            path,
            input_hash,
            template,
            units,
            no_sim,
            payload,
            quality,
        }) => {
            return batch_worker(
                &path,
                &input_hash,
                template.as_deref(),
                units.as_deref(),
                &RunOptions {
                    no_sim,
                    payload,
                    quality,
                    ..RunOptions::default()
                },
            )
        }
        Some(cli::Command::Summarize { file, csv, slowest }) => {
            return summarize(&file, csv.as_deref(), slowest)
        }
        Some(cli::Command::Tune {
            inputs,
            params,
            out,
            candidates,
            template,
            jobs,
        }) => {
            return tune(
                &inputs,
                &params,
                &out,
                candidates,
                template.as_deref(),
                jobs,
            )
        }
        None => {}
    }
    let options = RunOptions {
        no_sim: cli.no_sim,
        payload: cli.payload,
        quality: cli.quality,
        candidates: cli.candidates as usize,
        max_checked: cli.max_checked.map(|n| n as usize),
        export_mjcf: cli.export_mjcf,
        export_urdf: cli.export_urdf,
        report: cli.report,
        folder: None,
    };
    // Output folders are checked before any work, so an unwritable one costs nothing.
    for (flag, dir) in [
        ("--report", &options.report),
        ("--export-mjcf", &options.export_mjcf),
        ("--export-urdf", &options.export_urdf),
    ] {
        if let Some(d) = dir {
            check_writable_dir(d).context(flag)?;
        }
    }
    if cli.no_sim && cli.payload {
        eprintln!(
            "grasp-sim: warning: --payload is ignored with --no-sim (the payload search is part of the physics check)"
        );
    }
    let mut template = grasp_sim::batch::default_template();
    template.object.units = parse_units(&cli.units);
    let gravity = cli.gravity.as_deref().map(|g| match g {
        "six" => GravityMode::Six,
        _ => GravityMode::Down,
    });
    // Each input runs on its own: a bad one is reported on stderr and the others still run and
    // print; the exit status is the worst (2 bad input, 1 an expectation not met, 0).
    let mut status = 0u8;
    let mut out = std::io::stdout().lock();
    let mut names: std::collections::HashMap<String, usize> = Default::default();
    let writes_folders =
        options.report.is_some() || options.export_mjcf.is_some() || options.export_urdf.is_some();
    for path in &cli.scenarios {
        let item = if grasp_sim::mesh::MeshFormat::from_path(path).is_some() {
            grasp_sim::batch::Item::Mesh(path.clone())
        } else {
            grasp_sim::batch::Item::Scenario(path.clone())
        };
        if cli.units != "mm" && matches!(item, grasp_sim::batch::Item::Scenario(_)) {
            eprintln!(
                "grasp-sim: warning: {}: --units {} applies to bare meshes; a scenario gives its unit in `[object] units` (millimetres if it says none)",
                path.display(),
                cli.units
            );
        }
        let (report, folder) = match grasp_sim::batch::scenario_for(&item, &template).and_then(|mut s| {
            if let Some(g) = gravity {
                s.sim.gravity = g;
            }
            // Two inputs of one name (every file of a YCB-style set is `textured.obj`) would
            // write one output folder: the later ones get `NAME-2`, `NAME-3`, ... and are told.
            let mut options = options.clone();
            let count = names.entry(s.name.clone()).or_insert(0);
            *count += 1;
            if *count > 1 && writes_folders {
                let folder = format!("{}-{count}", s.name);
                eprintln!(
                    "grasp-sim: warning: {}: an earlier input has the name `{}`; its output folders are `{folder}`",
                    path.display(),
                    s.name
                );
                options.folder = Some(folder);
            }
            let spinner = progress_spinner(&s, &options);
            let r = run(&s, &options).map(|r| (r, options.folder));
            if let Some(b) = spinner {
                b.finish_and_clear();
            }
            r
        }) {
            Ok((r, folder)) => (r, folder),
            Err(e) => {
                let msg = format!("{e:#}").replace('\n', " ");
                // A scenario's mesh or hand file that cannot be read names that file; say which
                // scenario asked for it too.
                let scenario = path.display().to_string();
                // A file that is neither a `.toml` scenario nor a mesh by its extension (a
                // `.dae`, a `.txt`) was read as a scenario: say what is read.
                let hint = match item {
                    grasp_sim::batch::Item::Scenario(_)
                        if !path.is_dir()
                            && !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml")) =>
                    {
                        " (read as a scenario: grasp-sim reads scenarios from .toml files and meshes from .stl, .obj, .ply and .urdf)"
                    }
                    _ => "",
                };
                match item {
                    grasp_sim::batch::Item::Scenario(_) if !msg.starts_with(&scenario) => {
                        eprintln!("grasp-sim: error: {scenario}: {msg}{hint}")
                    }
                    _ => eprintln!("grasp-sim: error: {msg}{hint}"),
                }
                status = 2;
                continue;
            }
        };
        for w in &report.warnings {
            eprintln!("grasp-sim: warning: {w}");
        }
        let folder = folder.as_deref().unwrap_or(&report.scenario);
        if let Some(dir) = &options.report {
            eprintln!(
                "grasp-sim: report written to {}",
                dir.join(folder).join("report.html").display()
            );
        }
        if options.export_mjcf.is_some() {
            if let Some(scene) = &report.mjcf_scene {
                eprintln!("grasp-sim: MJCF scene written to {}", scene.display());
            } else {
                eprintln!(
                    "grasp-sim: warning: {}: no MJCF scene written: {}",
                    report.scenario,
                    report
                        .plan
                        .reason
                        .as_deref()
                        .unwrap_or("no grasp to export")
                );
            }
        }
        if cli.json {
            writeln!(out, "{}", grasp_sim::report::to_rounded_json(&report)?)?;
        } else {
            write!(out, "{}", report.summary())?;
        }
        out.flush()?;
        if report.expect.met == Some(false) {
            status = status.max(1);
        }
    }
    Ok(status)
}

/// A spinner with the elapsed time on stderr while one scenario runs, only when stderr is a
/// terminal (piped or redirected output stays clean) and the run does the physics check (the
/// plan alone takes milliseconds; `six` and `--payload` take seconds to tens of seconds).
fn progress_spinner(s: &Scenario, options: &RunOptions) -> Option<indicatif::ProgressBar> {
    use std::io::IsTerminal;
    if options.no_sim || !std::io::stderr().is_terminal() {
        return None;
    }
    let mut what = vec!["planning".to_string(), "physics check".to_string()];
    if s.sim.gravity == grasp_sim::scenario::GravityMode::Six {
        what[1] = "physics check (gravity six)".to_string();
    }
    if options.payload {
        what.push("payload search".to_string());
    }
    let b = indicatif::ProgressBar::new_spinner();
    b.set_style(
        indicatif::ProgressStyle::with_template("{spinner} {elapsed} {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
    );
    b.set_message(format!("{}: {}", s.name, what.join(", ")));
    b.enable_steady_tick(std::time::Duration::from_millis(120));
    b.tick();
    Some(b)
}

/// Creates `dir` if needed and checks a file can be written in it.
fn check_writable_dir(dir: &std::path::Path) -> anyhow::Result<()> {
    if dir.exists() && !dir.is_dir() {
        anyhow::bail!("{}: is a file, not a folder", dir.display());
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("{}: cannot create folder", dir.display()))?;
    let probe = dir.join(".grasp-sim-write-test");
    std::fs::write(&probe, b"")
        .and_then(|()| std::fs::remove_file(&probe))
        .with_context(|| format!("{}: cannot write in this folder", dir.display()))
}

/// Checks that `file` can be written later: its folder exists and takes a file.
fn check_writable_file(file: &std::path::Path) -> anyhow::Result<()> {
    let dir = file
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    if !dir.is_dir() {
        anyhow::bail!(
            "{}: cannot write: no folder {}",
            file.display(),
            dir.display()
        );
    }
    if file.is_dir() {
        anyhow::bail!(
            "{}: is a folder; give a file to write the results to (for example {})",
            file.display(),
            file.join("results.jsonl").display()
        );
    }
    let probe = dir.join(".grasp-sim-write-test");
    std::fs::write(&probe, b"")
        .and_then(|()| std::fs::remove_file(&probe))
        .with_context(|| format!("{}: cannot write in {}", file.display(), dir.display()))
}

fn tune(
    inputs: &[std::path::PathBuf],
    sweeps: &[grasp_sim::tune::Sweep],
    out: &std::path::Path,
    candidates: usize,
    template: Option<&std::path::Path>,
    jobs: Option<usize>,
) -> anyhow::Result<u8> {
    use grasp_sim::{batch, tune};
    use std::io::IsTerminal;
    let template = match template {
        Some(p) => Scenario::load(p)?,
        None => batch::default_template(),
    };
    let items = batch::expand(inputs)?;
    check_writable_dir(out).context("--out")?;
    let jobs = jobs.unwrap_or_else(default_jobs).max(1);
    let t0 = std::time::Instant::now();
    // A progress bar over objects x settings, on a terminal only (as batch's).
    let total = items.len() * tune::grid(sweeps).len();
    let bar = std::io::stderr().is_terminal().then(|| {
        let b = indicatif::ProgressBar::new(total as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} {elapsed} tune: {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b.set_message("loading objects");
        b.tick();
        b
    });
    let progress = |name: &str| {
        if let Some(b) = &bar {
            b.set_message(format!("{name} done at one setting"));
            b.inc(1);
        }
    };
    let result = tune::tune_with_progress(
        &items,
        &template,
        sweeps,
        candidates.max(1),
        jobs,
        &progress,
    );
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let result = result?;
    // Inputs that could not be loaded were left out; each is named, and the run exits 2.
    for (path, why) in &result.skipped {
        if why.contains(path.as_str()) {
            eprintln!("grasp-sim: error: {why}");
        } else {
            eprintln!("grasp-sim: error: {path}: {why}");
        }
    }
    std::fs::create_dir_all(out)
        .with_context(|| format!("{}: cannot create folder", out.display()))?;
    write_atomically(&out.join("tune.csv"), tune::to_csv(&result).as_bytes())?;
    write_atomically(
        &out.join("tune.json"),
        grasp_sim::report::to_rounded_json_pretty(&result)?.as_bytes(),
    )?;
    let plots = tune::plot(&result, out)?;
    print!("{}", tune::to_table(&result));
    let invalid = result
        .settings
        .iter()
        .filter(|s| s.invalid.is_some())
        .count();
    if invalid == result.settings.len() {
        anyhow::bail!(
            "--param: every setting is invalid, nothing to rank ({})",
            result.settings[0].invalid.as_deref().unwrap_or("")
        );
    }
    if invalid > 0 {
        eprintln!(
            "tune: {} invalid (not run, not ranked; the table says why)",
            grasp_sim::batch::plural(invalid, "setting")
        );
    }
    let best = &result.settings[result.best];
    let setting: Vec<String> = sweeps
        .iter()
        .zip(&best.values)
        .map(|(s, v)| format!("{}={v}", s.name))
        .collect();
    println!(
        "best: {} (hold rate {:.3}, mean payload margin {:.2}, mean translation {} mm) over {}",
        setting.join(" "),
        best.hold_rate,
        best.mean_payload_margin,
        best.mean_translation_mm
            .map_or("-".to_string(), |t| format!("{t:.2}")),
        batch::plural(result.counters.objects_loaded, "object")
    );
    let c = &result.counters;
    eprintln!(
        "tune: {} x {} in {:.1} s ({}); loaded {}, built {}, ran {} and {} ({} reused); wrote {}",
        batch::plural(result.settings.len(), "setting"),
        batch::plural(items.len(), "object"),
        t0.elapsed().as_secs_f64(),
        batch::plural(jobs, "job"),
        batch::plural(c.objects_loaded, "object"),
        batch::plural(c.domains_built, "domain"),
        batch::plural(c.plans, "plan"),
        batch::plural(c.sim_runs, "physics check"),
        c.sim_reused,
        plots
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(if result.skipped.is_empty() { 0 } else { 2 })
}

fn parse_units(s: &str) -> grasp_sim::mesh::LengthUnit {
    use grasp_sim::mesh::LengthUnit;
    // clap has checked the name against the same list.
    LengthUnit::from_name(s).unwrap_or_default()
}

fn default_jobs() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// The template for bare meshes: `--template` or the built-in one, with `--units` applied.
fn batch_template(
    template: Option<&std::path::Path>,
    units: Option<&str>,
) -> anyhow::Result<Scenario> {
    let mut template = match template {
        Some(p) => Scenario::load(p)?,
        None => grasp_sim::batch::default_template(),
    };
    if let Some(u) = units {
        template.object.units = parse_units(u);
    }
    Ok(template)
}

fn batch(args: &cli::BatchArgs) -> anyhow::Result<u8> {
    use grasp_sim::batch::{self, journal, Isolation, Record};
    use std::io::IsTerminal;
    if args.no_sim && args.payload {
        eprintln!(
            "grasp-sim: warning: --payload is ignored with --no-sim (the payload search is part of the physics check)"
        );
    }
    let options = RunOptions {
        no_sim: args.no_sim,
        payload: args.payload,
        quality: args.quality,
        ..RunOptions::default()
    };
    let template = batch_template(args.template.as_deref(), args.units.as_deref())?;
    if let Some(path) = &args.out {
        check_writable_file(path).context("--out")?;
    }
    let mut items = batch::expand(&args.inputs)?;
    if let Some(shard) = args.shard {
        items = shard.of(&items);
    }
    let keys = batch::keys(&items, &template, &options);
    if !args.merge.is_empty() {
        return batch_merge(args, &keys);
    }
    // Resuming: the lines the file already holds for these inputs, as they are now.
    let (journal, mut kept) = match (&args.out, args.resume) {
        (Some(path), true) => {
            let (j, read) = journal::Journal::open(path)?;
            if read.partial_bytes > 0 {
                eprintln!(
                    "grasp-sim: warning: {}: cut off a partial last line ({} bytes) an interrupted run left",
                    path.display(),
                    read.partial_bytes
                );
            }
            let mut kept: std::collections::HashMap<batch::Key, Record> = read
                .records
                .into_iter()
                .map(|(_, r)| (r.key.clone(), r))
                .collect();
            if args.retry_errors {
                kept.retain(|_, r| r.error().is_none());
            }
            (Some(j), kept)
        }
        _ => Default::default(),
    };
    let in_file: Vec<batch::Key> = kept.keys().cloned().collect();
    let todo: Vec<usize> = (0..items.len())
        .filter(|&i| !kept.contains_key(&keys[i]))
        .collect();
    if let Some(path) = args.out.as_ref().filter(|_| args.resume) {
        eprintln!(
            "resume: {} of {} already in {}; running {}",
            items.len() - todo.len(),
            batch::plural(items.len(), "object"),
            path.display(),
            todo.len()
        );
    }
    let run_items: Vec<batch::Item> = todo.iter().map(|&i| items[i].clone()).collect();
    let run_keys: Vec<batch::Key> = todo.iter().map(|&i| keys[i].clone()).collect();
    let jobs = args.jobs.unwrap_or_else(default_jobs).max(1);
    let total = run_items.len();
    let isolation = if args.in_process {
        Isolation::InProcess
    } else {
        Isolation::Process(batch_worker_command(args, (jobs / total.max(1)).max(1))?)
    };
    let bar = std::io::stderr().is_terminal().then(|| {
        let b = indicatif::ProgressBar::new(total as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} {elapsed} {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    });
    let done = std::sync::atomic::AtomicUsize::new(0);
    let append_error = std::sync::Mutex::new(None);
    let progress = |item: &batch::Item, r: &batch::ItemResult| {
        if let (Some(j), Ok(rec)) = (&journal, r) {
            if let Err(e) = j.append(rec) {
                append_error
                    .lock()
                    .unwrap_or_else(|p| p.into_inner())
                    .get_or_insert(e);
            }
        }
        let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        let what = match r {
            Ok(rec) => match rec.error() {
                Some(_) => "error".to_string(),
                None => format!(
                    "{} {}",
                    rec.value["plan"]["status"].as_str().unwrap_or("?"),
                    rec.value["sim"]["verdict"].as_str().unwrap_or("?")
                ),
            },
            Err(_) => "interrupted".to_string(),
        };
        match &bar {
            Some(b) => {
                b.set_message(format!("{}: {what}", item.path().display()));
                b.inc(1);
            }
            None => eprintln!("[{k}/{total}] {}: {what}", item.path().display()),
        }
    };
    let t0 = std::time::Instant::now();
    let results = batch::run_all(
        &run_items, &run_keys, &template, &options, jobs, &isolation, &progress,
    );
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    if let Some(e) = append_error.into_inner().unwrap_or_else(|p| p.into_inner()) {
        return Err(e.into());
    }
    let mut interrupted = 0;
    for (key, r) in run_keys.iter().zip(results) {
        match r {
            Ok(rec) => {
                if let Some(e) = rec.error() {
                    eprintln!("grasp-sim: error: {e}");
                }
                kept.insert(key.clone(), rec);
            }
            Err(batch::Interrupted(why)) => {
                interrupted += 1;
                eprintln!("grasp-sim: error: {why}");
            }
        }
    }
    // Everything in input order; a line for an input no longer given (or since edited) goes.
    let mut text = String::new();
    let mut lines = Vec::with_capacity(items.len());
    for key in &keys {
        if let Some(rec) = kept.get(key) {
            text.push_str(&rec.line);
            text.push('\n');
            lines.push(&rec.value);
        }
    }
    let current: std::collections::HashSet<&batch::Key> = keys.iter().collect();
    let dropped = in_file.iter().filter(|k| !current.contains(k)).count();
    match (&args.out, journal) {
        (Some(path), Some(j)) => {
            if dropped > 0 {
                eprintln!(
                    "grasp-sim: warning: {}: dropped {} for no current input (an input edited or removed, or other flags or template)",
                    path.display(),
                    batch::plural(dropped, "line")
                );
            }
            j.finish(text.as_bytes())?;
        }
        (Some(path), None) => journal::write_atomically(path, text.as_bytes())?,
        _ => std::io::stdout().lock().write_all(text.as_bytes())?,
    }
    let counts = batch::Counts::of(lines);
    eprintln!(
        "{}{}",
        batch::summary(&counts, total, t0.elapsed().as_secs_f64(), jobs),
        if interrupted > 0 {
            format!(
                "; {} interrupted (no line; --resume runs them again)",
                interrupted
            )
        } else {
            String::new()
        }
    );
    Ok(exit_status(&counts, interrupted))
}

/// 2 if an input could not be run, else 1 if an expectation was not met, else 0.
fn exit_status(counts: &grasp_sim::batch::Counts, interrupted: usize) -> u8 {
    if counts.errors > 0 || interrupted > 0 {
        2
    } else if counts.not_met > 0 {
        1
    } else {
        0
    }
}

/// The worker command for each object: this binary's hidden `batch-worker`, with the flags
/// that decide an object's result; each worker may use `threads` threads.
fn batch_worker_command(
    args: &cli::BatchArgs,
    threads: usize,
) -> anyhow::Result<grasp_sim::batch::Worker> {
    let program = std::env::current_exe()
        .context("cannot find this program to start a worker per object (try --in-process)")?;
    let mut wargs: Vec<std::ffi::OsString> = vec!["batch-worker".into()];
    if let Some(t) = &args.template {
        wargs.push("--template".into());
        wargs.push(t.into());
    }
    if let Some(u) = &args.units {
        wargs.push("--units".into());
        wargs.push(u.into());
    }
    if args.no_sim {
        wargs.push("--no-sim".into());
    }
    if args.payload {
        wargs.push("--payload".into());
    }
    if args.quality {
        wargs.push("--quality".into());
    }
    Ok(grasp_sim::batch::Worker {
        program,
        args: wargs,
        timeout: args.object_timeout.map(std::time::Duration::from_secs_f64),
        memory_limit_mib: args.object_memory,
        threads,
    })
}

/// `batch --merge`: the shard files' lines for these inputs, in input order, checked.
fn batch_merge(args: &cli::BatchArgs, keys: &[grasp_sim::batch::Key]) -> anyhow::Result<u8> {
    use grasp_sim::batch::{self, journal};
    let mut files = Vec::new();
    for m in &args.merge {
        if m.is_dir() {
            let mut found: Vec<std::path::PathBuf> = std::fs::read_dir(m)
                .with_context(|| format!("{}: cannot read folder", m.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.is_file() && p.extension().is_some_and(|e| e == "jsonl"))
                .collect();
            found.sort();
            files.extend(found);
        } else {
            files.push(m.clone());
        }
    }
    let mut records = Vec::new();
    for f in &files {
        let read = journal::read_records(f)?;
        if read.partial_bytes > 0 {
            eprintln!(
                "grasp-sim: warning: {}: ignoring a partial last line (its shard was interrupted)",
                f.display()
            );
        }
        records.extend(
            read.records
                .into_iter()
                .map(|(line, r)| (format!("{}:{line}", f.display()), r)),
        );
    }
    let merged = batch::merge(keys, records)?;
    let mut text = String::new();
    for r in &merged {
        text.push_str(&r.line);
        text.push('\n');
    }
    match &args.out {
        Some(path) => journal::write_atomically(path, text.as_bytes())?,
        None => std::io::stdout().lock().write_all(text.as_bytes())?,
    }
    let counts = batch::Counts::of(merged.iter().map(|r| &r.value));
    eprintln!(
        "merge: {} from {}, every input exactly once: {} planned, {} ungraspable; physics: {} hold, {} slip, {} drop; expectations: {} met, {} not met, {} not judged; {}",
        batch::plural(merged.len(), "object"),
        batch::plural(files.len(), "file"),
        counts.feasible,
        counts.ungraspable,
        counts.hold,
        counts.slip,
        counts.drop,
        counts.met,
        counts.not_met,
        counts.unjudged,
        batch::plural(counts.errors, "error")
    );
    Ok(exit_status(&counts, 0))
}

/// `batch-worker`: one object, its line on stdout.
fn batch_worker(
    path: &std::path::Path,
    input_hash: &str,
    template: Option<&std::path::Path>,
    units: Option<&str>,
    options: &RunOptions,
) -> anyhow::Result<u8> {
    use grasp_sim::batch;
    let template = batch_template(template, units)?;
    let item = batch::classify(path.to_path_buf()).ok_or_else(|| {
        anyhow::anyhow!(
            "{}: neither a scenario (.toml) nor a mesh (.stl, .obj, .ply, .urdf)",
            path.display()
        )
    })?;
    let key = batch::Key {
        input: path.display().to_string(),
        input_hash: input_hash.to_string(),
    };
    let record = batch::run_one(&item, &key, &template, options);
    let mut out = std::io::stdout().lock();
    writeln!(out, "{}", record.line)?;
    out.flush()?;
    Ok(0)
}

/// `summarize`: the dataset report on stdout, and the CSV.
fn summarize(
    file: &std::path::Path,
    csv: Option<&std::path::Path>,
    slowest: usize,
) -> anyhow::Result<u8> {
    use grasp_sim::summarize::Summary;
    if let Some(c) = csv {
        check_writable_file(c).context("--csv")?;
    }
    let summary = Summary::read(file)?;
    for w in &summary.warnings {
        eprintln!("grasp-sim: warning: {}: {w}", file.display());
    }
    print!("{}", summary.to_text(&file.display().to_string(), slowest));
    if let Some(c) = csv {
        grasp_sim::batch::journal::write_atomically(c, summary.to_csv().as_bytes())?;
        eprintln!("summarize: wrote {}", c.display());
    }
    Ok(0)
}

/// Writes `bytes` to `path` through a temporary file beside it, so a reader never sees half a
/// file.
fn write_atomically(path: &std::path::Path, bytes: &[u8]) -> anyhow::Result<()> {
    Ok(grasp_sim::batch::journal::write_atomically(path, bytes)?)
}

fn gen_hard_assets(out: &std::path::Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(out)
        .with_context(|| format!("{}: cannot create folder", out.display()))?;
    for (name, mesh) in grasp_sim::objects::hard::hard_objects() {
        let path = out.join(format!("{name}.stl"));
        write_atomically(&path, &mesh.to_binary_stl())?;
        println!("{}: {} triangles", path.display(), mesh.triangles.len());
    }
    Ok(())
}

fn gen_assets(out: &std::path::Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(out)
        .with_context(|| format!("{}: cannot create folder", out.display()))?;
    for (name, mesh) in grasp_sim::objects::thesis_objects() {
        let path = out.join(format!("{name}.stl"));
        let tmp = out.join(format!(".{name}.stl.tmp"));
        std::fs::write(&tmp, mesh.to_binary_stl())
            .and_then(|()| std::fs::rename(&tmp, &path))
            .with_context(|| format!("{}: cannot write", path.display()))?;
        println!("{}: {} triangles", path.display(), mesh.triangles.len());
    }
    // The tuning set, each object with a scenario (the thesis hand, defaults, expected to hold).
    let train = out.join("train");
    std::fs::create_dir_all(&train)
        .with_context(|| format!("{}: cannot create folder", train.display()))?;
    for (name, mesh) in grasp_sim::objects::training_objects() {
        let path = train.join(format!("{name}.stl"));
        write_atomically(&path, &mesh.to_binary_stl())?;
        let scenario = format!(
            "# Tuning set (issue 6), generated by `grasp-sim gen-assets`. The expected outcome is the desired\n# one: `grasp-sim tune` ranks planner settings by how many of these objects end up held.\nname = \"train_{name}\"\n\n[object]\nmesh = \"{name}.stl\"\ndensity_kg_m3 = 500.0\nfriction = 0.3\n\n[hand]\nfile = \"thesis\"\n\n[expect]\noutcome = \"hold\"\n"
        );
        write_atomically(&train.join(format!("{name}.toml")), scenario.as_bytes())?;
        println!("{}: {} triangles", path.display(), mesh.triangles.len());
    }
    Ok(())
}
