//! What the study examples (`protocols`, `early_rule`) share: `--set KEY=VALUE` for a scenario's
//! `[sim]` table, and loading a scenario with those keys set.

use grasp_sim::scenario::Scenario;

/// `KEY=VALUE` (a TOML value) as a `[sim]` key and its value.
pub fn parse_set(kv: &str) -> (String, toml::Value) {
    let (k, v) = kv.split_once('=').expect("KEY=VALUE");
    let v: toml::Table = toml::from_str(&format!("v = {v}")).expect("a TOML value");
    (k.to_string(), v["v"].clone())
}

/// The scenario at `file` with every `sets` key written into its `[sim]` table; a scenario that
/// does not parse ends the program with its error and exit status 2.
pub fn load_with(file: &str, sets: &[(String, toml::Value)]) -> Scenario {
    let path = std::path::Path::new(file);
    let mut table: toml::Table = toml::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    if !sets.is_empty() {
        let sim = table
            .entry("sim")
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        for (k, v) in sets {
            sim.as_table_mut().unwrap().insert(k.clone(), v.clone());
        }
    }
    match Scenario::parse(&toml::to_string(&table).unwrap(), path) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{file}: {e}");
            std::process::exit(2);
        }
    }
}
