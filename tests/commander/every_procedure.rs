//! Every procedure of every built-in profile, found in the profiles themselves (a new one
//! is covered without touching this file), runs to completion on the demo bus with the
//! simulated drive of that profile (`cotui demo --node 2=PROFILE` in-process), each from a
//! freshly powered drive; and the drives do what the procedures asked.

use cotui::cli::bind::bindings_for_demo;
use cotui::command::run::{plan, run};
use cotui::sim::Simulation;
use cotui::sim::demo::Demo;
use cotui::sim::drive::Drive;
use cotui::sim::profile::DriveProfile;
use std::time::Duration;

const NODE: u8 = 2;

/// What a procedure leaves behind, read from the simulated drive 30 s after it ended
/// (simulated time: the Syn-tron's 1000 ms ramp to 300 rpm and 60000 pulses take a while).
const EFFECTS: &[(&str, &str, u16, u8, i64)] = &[
    ("aimotor", "pv", 0x606C, 0, 10_000),
    ("aimotor", "pp", 0x6064, 0, 100_500),
    ("aimotor", "csv", 0x606C, 0, 1000),
    ("aimotor", "cst", 0x6077, 0, 100),
    ("syntron-ds", "pp", 0x6064, 0, 60_000),
    ("dexmart-dev", "encoder_speed_m1", 0x3046, 5, 3000),
    ("dexmart-dev", "encoder_position_m2", 0x304A, 23, 100),
    ("dexmart-dev", "hall_speed_m2", 0x304A, 5, 3000),
    ("aqmd2405", "rpdo_speed", 0x2101, 0, 1000),
];

/// Runs `procedure` of `profile` with its defaults on a new demo; the run's JSON, the
/// planned step count and the value of each effect object afterwards.
fn run_one(profile: &str, procedure: &str) -> (serde_json::Value, usize, Vec<i64>) {
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .start_paused(true)
        .build()
        .unwrap();
    rt.block_on(async {
        let model = DriveProfile::model(profile).unwrap_or_else(|| panic!("no simulated drive for {profile}"));
        let sim = Simulation::demo_with(vec![Drive::new(NODE, model)]);
        let bindings = bindings_for_demo(&sim, &[], &[]).unwrap();
        let demo = Demo::spawn(sim, false);
        let dict = bindings.dictionary(NODE);
        let p = plan(dict, NODE, procedure, &[]).unwrap_or_else(|e| panic!("{profile} {procedure}: {e}"));
        let run = run(&demo.bus, dict, &p, 500, &mut |_| {})
            .await
            .unwrap_or_else(|e| panic!("{profile} {procedure}: {e}"));
        let v = serde_json::to_value(run).unwrap();
        tokio::time::sleep(Duration::from_secs(30)).await;
        let s = demo.sim.lock().unwrap();
        let od = s.drive(NODE).unwrap().objects();
        let effects = EFFECTS
            .iter()
            .filter(|e| (e.0, e.1) == (profile, procedure))
            .map(|e| od.int(e.2, e.3))
            .collect();
        (v, p.steps.len(), effects)
    })
}

#[test]
fn every_procedure_of_every_built_in_profile_runs_to_completion_on_its_simulated_drive() {
    let mut ran = Vec::new();
    for profile in cotui::od::bind::builtin_names() {
        let Some(Ok((p, _))) = cotui::od::bind::shared_builtin(profile) else {
            panic!("built-in profile {profile} does not load");
        };
        for procedure in p.procedures.keys() {
            let (v, steps, effects) = run_one(profile, procedure);
            assert_eq!(v["ok"], true, "{profile} {procedure}: {v}");
            assert_eq!(
                v["steps"].as_array().map(Vec::len),
                Some(steps),
                "{profile} {procedure}: every step done"
            );
            let expected: Vec<i64> = EFFECTS
                .iter()
                .filter(|e| (e.0, e.1) == (profile, procedure.as_str()))
                .map(|e| e.4)
                .collect();
            assert_eq!(effects, expected, "{profile} {procedure}: what the drive did");
            ran.push(format!("{profile}/{procedure}"));
        }
    }
    // The four seed devices' procedures, all of them (7 + 11 + 8 + 3 today, more later).
    for profile in ["aimotor", "syntron-ds", "dexmart-dev", "aqmd2405"] {
        assert!(ran.iter().any(|r| r.starts_with(&format!("{profile}/"))), "{ran:?}");
    }
    for e in EFFECTS {
        assert!(ran.contains(&format!("{}/{}", e.0, e.1)), "{}/{} not run", e.0, e.1);
    }
    assert!(ran.len() >= 29, "{ran:?}");
}
