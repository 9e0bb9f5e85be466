//! `lss` palette/CLI lines run by the executor against simulated drives without node-ID
//! (`Drive::new(0xFF, ..)`, as `cotui sim --node ff=servo@SERIAL` runs them), tokio time
//! paused: fresh drives get their node-IDs one by one, then answer SDO there.

use cotui::command::sdo::upload;
use cotui::command::{CommandError, ExitCode, execute, parse_command};
use cotui::od::bind::Bindings;
use cotui::sim::Simulation;
use cotui::sim::demo::Demo;
use cotui::sim::drive::Drive;
use cotui::sim::spec::parse_node;

fn fresh_drives(specs: &[&str]) -> Demo {
    let drives = specs
        .iter()
        .map(|s| {
            let (node, profile) = parse_node(s).unwrap();
            Drive::new(node, profile)
        })
        .collect();
    Demo::spawn(Simulation::new(drives, 0), false)
}

async fn run(d: &Demo, line: &str) -> Result<serde_json::Value, CommandError> {
    let cmd = parse_command(line).unwrap();
    Ok(execute(&d.bus, &cmd, &Bindings::new()).await?.json())
}

#[tokio::test(start_paused = true)]
async fn assign_then_reset_comm_puts_fresh_drives_on_their_node_ids() {
    let d = fresh_drives(&["ff=servo@0x99", "ff=servo@0x1234"]);
    let e = run(&d, "lss inquire node").await.unwrap_err();
    assert_eq!(e.exit_code(), ExitCode::Timeout);
    assert!(
        e.to_string().contains("no answer from an LSS slave within 100 ms"),
        "{e}"
    );

    let found = run(&d, "lss fastscan").await.unwrap();
    assert_eq!(
        (found["found"].as_bool(), found["address"]["serial"].as_u64()),
        (Some(true), Some(0x99))
    );
    assert_eq!(run(&d, "lss inquire serial").await.unwrap()["value"], 0x99);
    run(&d, "lss set-node 10").await.unwrap();
    run(&d, "lss switch wait").await.unwrap();
    let assigned = run(&d, "lss assign 11 --store").await.unwrap();
    assert_eq!(assigned["address"]["serial"], 0x1234);
    assert_eq!(assigned["stored"], true);
    let none = run(&d, "lss assign 12").await.unwrap_err();
    assert_eq!(none.exit_code(), ExitCode::Timeout);

    run(&d, "nmt reset-comm 0").await.unwrap();
    assert_eq!(
        upload(&d.bus, 10, 0x1018, 4, false, 500).await.unwrap(),
        0x99u32.to_le_bytes()
    );
    assert_eq!(
        upload(&d.bus, 11, 0x1018, 4, false, 500).await.unwrap(),
        0x1234u32.to_le_bytes()
    );
}

#[tokio::test(start_paused = true)]
async fn select_by_the_inquired_address_then_bit_rate_and_identify() {
    // Nothing in configuration state yet: no answer.
    let d = fresh_drives(&["ff=servo@0x5"]);
    let id = run(&d, "lss inquire vendor").await;
    assert!(id.is_err());
    run(&d, "lss switch global config").await.unwrap();
    let vendor = run(&d, "lss inquire vendor").await.unwrap()["value"].as_u64().unwrap() as u32;
    let product = run(&d, "lss inquire product").await.unwrap()["value"].as_u64().unwrap() as u32;
    let rev = run(&d, "lss inquire revision").await.unwrap()["value"]
        .as_u64()
        .unwrap() as u32;
    run(&d, "lss switch wait").await.unwrap();
    let sel = run(&d, &format!("lss select {vendor} {product} {rev} 5"))
        .await
        .unwrap();
    assert_eq!(sel["address"]["serial"], 5);
    let r = run(&d, "lss set-bitrate 250").await.unwrap();
    assert_eq!(r["bit_rate"], "250 kbit/s");
    let ident = run(&d, &format!("lss identify {vendor} {product} 0 {rev} 1 9"))
        .await
        .unwrap();
    assert_eq!(ident["identified"], 1);
    run(&d, "lss switch wait").await.unwrap();
    assert_eq!(run(&d, "lss identify-unconfigured").await.unwrap()["identified"], 1);
}
