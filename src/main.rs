//! The `grasp-sim` binary: parse flags, dispatch to the library's commands, map the result to an
//! exit code. Progress bars and spinners (on a terminal only) are drawn here.

mod cli;

use clap::Parser;
use grasp_sim::pipeline::{
    check_output_dir, check_output_file, inputs, lock_output_dir, Progress, RunOptions,
};
use grasp_sim::scenario::{GravityMode, Scenario};
use std::io::IsTerminal;
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
    match dispatch(cli) {
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

/// Runs the command the flags name; returns the exit status.
fn dispatch(cli: cli::Cli) -> anyhow::Result<u8> {
    use cli::Command;
    if let Some(dir) = &cli.collider_cache {
        use_collider_cache(dir)?;
    }
    match cli.command {
        Some(Command::GenAssets { out, hard: true }) => {
            grasp_sim::assets::write_hard_assets(&out).map(|()| 0)
        }
        Some(Command::GenAssets { out, hard: false }) => {
            grasp_sim::assets::write_thesis_assets(&out).map(|()| 0)
        }
        Some(Command::Batch(args)) => {
            let request = args.request();
            grasp_sim::batch::command::run(&request, &Bar::batch())
        }
        Some(Command::BatchWorker {
            path,
            input_hash,
            template,
            units,
            flags,
        }) => {
            let args = grasp_sim::batch::command::WorkerArgs {
                template,
                units: units.map(Into::into),
                flags: flags.into(),
            };
            grasp_sim::batch::command::run_worker(&path, &input_hash, &args)
        }
        Some(Command::Summarize { file, csv, slowest }) => {
            summarize(&file, csv.as_deref(), slowest)
        }
        Some(Command::Hand {
            action: cli::HandCommand::Show { file, svg },
        }) => grasp_sim::hand_show::run(&file, svg.as_deref()),
        Some(Command::Tune(args)) => match &args.labels {
            Some(labels) => grasp_sim::tune::order::run(
                labels,
                (args.objective, args.order),
                args.folds as usize,
                &args.out,
            ),
            None => grasp_sim::tune::command::run(&args.request(), &Bar::tune()),
        },
        Some(Command::Label(args)) => {
            grasp_sim::label::command::run(&args.request(), &Bar::batch())
        }
        Some(c @ (Command::LabelWorker { .. } | Command::Check { .. })) => label_command(c),
        None => run_inputs(cli),
    }
}

/// Names `dir` (made if missing) as the collider cache of this process and of the workers it
/// starts, through the environment they inherit; before any thread starts.
fn use_collider_cache(dir: &std::path::Path) -> anyhow::Result<()> {
    use anyhow::Context;
    if dir.exists() && !dir.is_dir() {
        anyhow::bail!("--collider-cache {}: is not a folder", dir.display());
    }
    std::fs::create_dir_all(dir)
        .and_then(|()| grasp_sim::files::check_writable_dir(dir))
        .with_context(|| format!("--collider-cache {}: cannot write there", dir.display()))?;
    std::env::set_var(grasp_sim::sim::collider_cache::ENV, dir);
    Ok(())
}

/// `label-worker` and `check --grasps`.
fn label_command(command: cli::Command) -> anyhow::Result<u8> {
    use grasp_sim::label::command::{self as label, CheckRequest, WorkerArgs};
    match command {
        cli::Command::LabelWorker {
            path,
            input_hash,
            template,
            units,
            gravity,
            grasps,
            samples,
            candidates,
            export_mjcf,
            mujoco_fraction,
            skip,
        } => {
            let args = WorkerArgs {
                template,
                units: units.map(Into::into),
                params: grasp_sim::label::LabelParams {
                    grasps,
                    samples,
                    candidates,
                },
                gravity: gravity.map(Into::into),
                export: export_mjcf.map(|dir| grasp_sim::label::object::MjcfExport {
                    dir,
                    fraction: mujoco_fraction,
                }),
            };
            label::run_worker(&path, &input_hash, &args, &skip.into_iter().collect())
        }
        cli::Command::Check {
            grasps,
            input,
            samples,
            gravity,
            units,
            out,
        } => {
            let request = CheckRequest {
                grasps,
                input,
                units: units.map(Into::into),
                samples: samples as usize,
                gravity: gravity.map(Into::into),
                out,
            };
            label::check(&request, &Bar::batch())
        }
        _ => unreachable!("label_command is called for label-worker and check only"),
    }
}

/// The main command: every scenario or mesh on the command line, in turn.
fn run_inputs(cli: cli::Cli) -> anyhow::Result<u8> {
    let options = RunOptions {
        candidates: cli.candidates as usize,
        max_checked: cli.max_checked.map(|n| n as usize),
        export_mjcf: cli.export_mjcf,
        export_urdf: cli.export_urdf,
        report: cli.report,
        ..RunOptions::from(grasp_sim::RunFlags::from(cli.flags))
    };
    // Each output folder locked once for the whole run, though two flags name the same one.
    let mut locks: Vec<(std::path::PathBuf, grasp_sim::files::FolderLock)> = Vec::new();
    for (flag, dir) in [
        ("--report", &options.report),
        ("--export-mjcf", &options.export_mjcf),
        ("--export-urdf", &options.export_urdf),
    ] {
        if let Some(d) = dir {
            anyhow::Context::context(check_output_dir(d), flag)?;
            let same = std::fs::canonicalize(d).unwrap_or_else(|_| d.clone());
            if !locks.iter().any(|(p, _)| *p == same) {
                let lock = anyhow::Context::context(lock_output_dir(d), flag)?;
                locks.push((same, lock));
            }
        }
    }
    let command_line = inputs::CommandLine {
        options,
        units: cli.units.into(),
        gravity: cli.gravity.map(GravityMode::from),
        samples: cli.samples.map(|n| n as usize),
        json: cli.json,
        time_limit: Some(std::time::Duration::from_secs_f64(cli.time_limit)),
    };
    let mut out = std::io::stdout().lock();
    inputs::run_inputs(&cli.scenarios, &command_line, &mut out, &spinner)
}

/// A spinner with the elapsed time on stderr while one scenario runs, only when stderr is a
/// terminal (piped or redirected output stays clean) and the run does the physics check (the
/// plan alone takes milliseconds; `six` and `--payload` take seconds to tens of seconds).
fn spinner(s: &Scenario, options: &RunOptions) -> Option<Box<dyn FnOnce()>> {
    if options.no_sim || !std::io::stderr().is_terminal() {
        return None;
    }
    let mut what = vec!["planning", "physics check"];
    if s.sim.gravity == GravityMode::Six {
        what[1] = "physics check (gravity six)";
    }
    if options.payload {
        what.push("payload search");
    }
    let b = indicatif::ProgressBar::new_spinner();
    b.set_style(
        indicatif::ProgressStyle::with_template("{spinner} {elapsed} {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
    );
    b.set_message(format!("{}: {}", s.name, what.join(", ")));
    b.enable_steady_tick(std::time::Duration::from_millis(120));
    b.tick();
    Some(Box::new(move || b.finish_and_clear()))
}

/// A progress bar on a terminal; elsewhere, a line per step (`batch`) or nothing (`tune`).
struct Bar {
    template: &'static str,
    first_message: &'static str,
    lines: bool,
    bar: std::sync::OnceLock<indicatif::ProgressBar>,
}

impl Bar {
    fn batch() -> Bar {
        Bar {
            template: "{bar:40} {pos}/{len} {elapsed} {msg}",
            first_message: "",
            lines: true,
            bar: Default::default(),
        }
    }

    fn tune() -> Bar {
        Bar {
            template: "{bar:40} {pos}/{len} {elapsed} tune: {msg}",
            first_message: "loading objects",
            lines: false,
            bar: Default::default(),
        }
    }
}

impl Progress for Bar {
    fn begin(&self, total: usize) {
        if !std::io::stderr().is_terminal() {
            return;
        }
        let b = indicatif::ProgressBar::new(total as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template(self.template)
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        if !self.first_message.is_empty() {
            b.set_message(self.first_message);
            b.tick();
        }
        let _ = self.bar.set(b);
    }

    fn step(&self, done: usize, total: usize, message: &str) {
        match self.bar.get() {
            Some(b) => {
                b.set_message(message.to_string());
                b.inc(1);
            }
            None if self.lines => eprintln!("[{done}/{total}] {message}"),
            None => {}
        }
    }

    fn end(&self) {
        if let Some(b) = self.bar.get() {
            b.finish_and_clear();
        }
    }
}

/// `summarize`: the dataset report on stdout, and the CSV.
fn summarize(
    file: &std::path::Path,
    csv: Option<&std::path::Path>,
    slowest: usize,
) -> anyhow::Result<u8> {
    use grasp_sim::summarize::Summary;
    if let Some(c) = csv {
        anyhow::Context::context(check_output_file(c), "--csv")?;
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
