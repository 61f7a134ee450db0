//! The `grasp-sim` binary: parse flags, run, map the result to an exit code.

mod cli;

use anyhow::Context;
use clap::Parser;
use grasp_sim::{run, scenario::Scenario, RunOptions};
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
        Err(e) => {
            eprintln!("grasp-sim: error: {}", format!("{e:#}").replace('\n', " "));
            ExitCode::from(2)
        }
    }
}

fn real_main(cli: cli::Cli) -> anyhow::Result<u8> {
    match cli.command {
        Some(cli::Command::GenAssets { out }) => return gen_assets(&out).map(|()| 0),
        Some(cli::Command::Batch {
            inputs,
            template,
            units,
            out,
            jobs,
            shard,
            no_sim,
            payload,
        }) => {
            if no_sim && payload {
                eprintln!(
                    "grasp-sim: warning: --payload is ignored with --no-sim (the payload search is part of the physics check)"
                );
            }
            let options = RunOptions {
                no_sim,
                payload,
                ..RunOptions::default()
            };
            return batch(
                &inputs,
                template.as_deref(),
                units.as_deref(),
                out.as_deref(),
                jobs,
                shard.as_deref(),
                &options,
            );
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
        candidates: cli.candidates as usize,
        max_checked: cli.max_checked.map(|n| n as usize),
        export_mjcf: cli.export_mjcf,
        export_urdf: cli.export_urdf,
        report: cli.report,
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
    // Each input runs on its own: a bad one is reported on stderr and the others still run and
    // print; the exit status is the worst (2 bad input, 1 an expectation not met, 0).
    let mut status = 0u8;
    let mut out = std::io::stdout().lock();
    for path in &cli.scenarios {
        let item = if grasp_sim::mesh::MeshFormat::from_path(path).is_some() {
            grasp_sim::batch::Item::Mesh(path.clone())
        } else {
            grasp_sim::batch::Item::Scenario(path.clone())
        };
        let report = match grasp_sim::batch::scenario_for(&item, &template).and_then(|s| {
            let spinner = progress_spinner(&s, &options);
            let r = run(&s, &options);
            if let Some(b) = spinner {
                b.finish_and_clear();
            }
            r
        }) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("grasp-sim: error: {}", format!("{e:#}").replace('\n', " "));
                status = 2;
                continue;
            }
        };
        for w in &report.warnings {
            eprintln!("grasp-sim: warning: {w}");
        }
        if let Some(dir) = &options.report {
            eprintln!(
                "grasp-sim: report written to {}",
                dir.join(&report.scenario).join("report.html").display()
            );
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
    let probe = dir.join(".grasp-sim-write-test");
    std::fs::write(&probe, b"")
        .and_then(|()| std::fs::remove_file(&probe))
        .with_context(|| format!("{}: cannot write in {}", file.display(), dir.display()))
}

fn tune(
    inputs: &[std::path::PathBuf],
    params: &[String],
    out: &std::path::Path,
    candidates: usize,
    template: Option<&std::path::Path>,
    jobs: Option<usize>,
) -> anyhow::Result<u8> {
    use grasp_sim::{batch, tune};
    use std::io::IsTerminal;
    let sweeps = params
        .iter()
        .map(|p| tune::parse_sweep(p).map_err(|m| anyhow::anyhow!("--param {m}")))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let template = match template {
        Some(p) => Scenario::load(p)?,
        None => batch::default_template(),
    };
    let items = batch::expand(inputs)?;
    check_writable_dir(out).context("--out")?;
    let jobs = jobs.unwrap_or_else(default_jobs).max(1);
    let t0 = std::time::Instant::now();
    // A progress bar over objects x settings, on a terminal only (as batch's).
    let total = items.len() * tune::grid(&sweeps).len();
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
        &sweeps,
        candidates.max(1),
        jobs,
        &progress,
    );
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let result = result?;
    std::fs::create_dir_all(out)
        .with_context(|| format!("{}: cannot create folder", out.display()))?;
    write_atomically(&out.join("tune.csv"), tune::to_csv(&result).as_bytes())?;
    write_atomically(
        &out.join("tune.json"),
        grasp_sim::report::to_rounded_json_pretty(&result)?.as_bytes(),
    )?;
    let plots = tune::plot(&result, out).map_err(|m| anyhow::anyhow!(m))?;
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
        batch::plural(items.len(), "object")
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
    Ok(0)
}

fn parse_units(s: &str) -> grasp_sim::mesh::LengthUnit {
    use grasp_sim::mesh::LengthUnit;
    match s {
        "m" => LengthUnit::M,
        "inch" => LengthUnit::Inch,
        _ => LengthUnit::Mm,
    }
}

fn default_jobs() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

#[allow(clippy::too_many_arguments)]
fn batch(
    inputs: &[std::path::PathBuf],
    template: Option<&std::path::Path>,
    units: Option<&str>,
    out: Option<&std::path::Path>,
    jobs: Option<usize>,
    shard: Option<&str>,
    options: &RunOptions,
) -> anyhow::Result<u8> {
    use grasp_sim::batch;
    use std::io::IsTerminal;
    let mut template = match template {
        Some(p) => Scenario::load(p)?,
        None => batch::default_template(),
    };
    if let Some(u) = units {
        template.object.units = parse_units(u);
    }
    if let Some(path) = out {
        check_writable_file(path).context("--out")?;
    }
    let mut items = batch::expand(inputs)?;
    if let Some(s) = shard {
        let (k, n) = batch::parse_shard(s).map_err(|m| anyhow::anyhow!("--shard: {m}"))?;
        items = batch::shard(&items, k, n);
    }
    let jobs = jobs.unwrap_or_else(default_jobs).max(1);
    let total = items.len();
    let bar = std::io::stderr().is_terminal().then(|| {
        let b = indicatif::ProgressBar::new(total as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} {elapsed} {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    });
    let done = std::sync::atomic::AtomicUsize::new(0);
    let progress = |item: &batch::Item, r: &batch::ItemResult| {
        let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        let what = match r {
            Ok(rep) => format!("{} {}", rep.plan.status, rep.sim.verdict),
            Err(_) => "error".to_string(),
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
    let results = batch::run_all(&items, &template, options, jobs, &progress);
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let mut text = String::new();
    let mut errors = 0;
    let mut not_met = 0;
    for (item, r) in items.iter().zip(&results) {
        let line = match r {
            Ok(rep) => {
                not_met += usize::from(rep.expect.met == Some(false));
                grasp_sim::report::to_rounded_json(rep)?
            }
            Err(e) => {
                errors += 1;
                eprintln!("grasp-sim: error: {e}");
                serde_json::json!({"scenario": item.path().display().to_string(), "error": e})
                    .to_string()
            }
        };
        text.push_str(&line);
        text.push('\n');
    }
    match out {
        Some(path) => write_atomically(path, text.as_bytes())?,
        None => std::io::stdout().lock().write_all(text.as_bytes())?,
    }
    eprintln!(
        "{}",
        batch::summary(&results, t0.elapsed().as_secs_f64(), jobs)
    );
    Ok(if errors > 0 {
        2
    } else if not_met > 0 {
        1
    } else {
        0
    })
}

/// Writes `bytes` to `path` through a temporary file beside it, so a reader never sees half a
/// file.
fn write_atomically(path: &std::path::Path, bytes: &[u8]) -> anyhow::Result<()> {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = dir.join(format!(".{name}.tmp"));
    std::fs::write(&tmp, bytes)
        .and_then(|()| std::fs::rename(&tmp, path))
        .with_context(|| format!("{}: cannot write", path.display()))
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
