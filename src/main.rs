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
    if let Some(cli::Command::GenAssets { out }) = cli.command {
        return gen_assets(&out).map(|()| 0);
    }
    let options = RunOptions {
        no_sim: cli.no_sim,
        payload: cli.payload,
        candidates: cli.candidates as usize,
        export_mjcf: cli.export_mjcf,
        export_urdf: cli.export_urdf,
    };
    // Everything is run before anything is printed, so bad input anywhere leaves no partial output.
    let mut reports = Vec::new();
    for path in &cli.scenarios {
        let scenario = Scenario::load(path)?;
        let report = run(&scenario, &options)?;
        reports.push((scenario, report));
    }
    let mut out = std::io::stdout().lock();
    let mut all_met = true;
    for (_, report) in &reports {
        for w in &report.warnings {
            eprintln!("grasp-sim: warning: {w}");
        }
        if cli.json {
            writeln!(out, "{}", serde_json::to_string(report)?)?;
        } else {
            write!(out, "{}", report.summary())?;
        }
        all_met &= report.expect.met != Some(false);
    }
    Ok(if all_met { 0 } else { 1 })
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
    Ok(())
}
