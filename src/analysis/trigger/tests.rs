use super::*;
use crate::analysis::filter::NoNames;

fn parse(t: &str) -> Result<Trigger, FilterError> {
    Trigger::parse(t, &NoNames)
}

#[test]
fn events_incidents_filters_and_sequences_parse() {
    assert_eq!(parse("hb lost").unwrap().first, Atom::Event(BusEvent::HeartbeatLost));
    assert_eq!(parse(" Bus-Off ").unwrap().first, Atom::Event(BusEvent::BusOff));
    assert_eq!(
        parse("incident drive_fault").unwrap().first,
        Atom::Incident(Problem::DriveFault)
    );
    assert!(matches!(parse("node 3 and abort").unwrap().first, Atom::Filter(_)));
    let t = parse("bootup then emcy within 2s").unwrap();
    assert_eq!(t.first, Atom::Event(BusEvent::BootUp));
    assert!(matches!(t.then, Some((Atom::Filter(_), 2_000_000_000))));
    // A quoted `then` is text of the filter.
    assert!(parse("\"a then b\"").unwrap().then.is_none());
    assert_eq!(parse("node 3 and abort").unwrap().slug(), "node-3-and-abort");
}

#[test]
fn a_bad_trigger_says_its_column() {
    let e = parse("emcy then node 3 bogus within 2s").unwrap_err();
    assert_eq!(e.column, 18, "{e}");
    let e = parse("node 3 bogus").unwrap_err();
    assert_eq!(e.column, 8, "{e}");
    let e = parse("incident frobnicate").unwrap_err();
    assert_eq!(e.column, 10, "{e}");
    assert!(e.message.contains("drive_fault"), "{e}");
    let e = parse("emcy then hb lost").unwrap_err();
    assert!(e.message.contains("within 2s"), "{e}");
    let e = parse("emcy then hb lost within soon").unwrap_err();
    assert_eq!(e.column, 26, "{e}");
    assert!(parse("").is_err());
    assert_eq!(parse("then emcy within 1s").unwrap_err().column, 1);
}
