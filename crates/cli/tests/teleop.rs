//! `twoport teleop`: two devices through one law, as a lab runs it.

#[path = "../../../tests/support/cli.rs"]
mod support;

const TWOPORT: support::Tool = support::Tool {
    bin: env!("CARGO_BIN_EXE_twoport"),
    root: concat!(env!("CARGO_MANIFEST_DIR"), "/../.."),
};

const CAPSTAN: &str = "models/capstan.toml";
const TWO_MASS: &str = "models/two_mass.toml";

/// `teleop verify` between two capstan handles, then `law` (its words).
fn between_handles(law: &str) -> Vec<String> {
    format!("teleop verify --master {CAPSTAN} --slave {CAPSTAN} {law}")
        .split_whitespace()
        .map(String::from)
        .collect()
}

/// `teleop verify --json` of position-position at `k` (N/m), no damping,
/// between two capstan handles, with `delay` ticks each way.
fn pp(k: &str, delay: &str) -> serde_json::Value {
    let args = between_handles(&format!(
        "--delay {delay} --json position-position --k {k} --b 0"
    ));
    TWOPORT.json(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

/// Two rigid capstan handles (0.25 kg, 2 N s/m each): their relative
/// motion is one mass on the sampled spring `2k` with damping `b`, whose
/// edge is Colgate's `k < b/T` = 2,000 N/m. The search finds nothing 5%
/// below it and growth 5% above; two ticks of delay break the gains
/// below it.
#[test]
fn position_position_between_two_handles_meets_colgates_edge() {
    let below = pp("1900", "0");
    assert_eq!(below["unstable"], false, "{below}");
    assert_eq!(below["gains"]["k_m_npm"], 1900.0);
    assert_eq!(below["gains"]["k_s_npm"], 1900.0);
    assert_eq!(below["delay_ticks"], 0);
    let above = pp("2100", "0");
    assert_eq!(above["unstable"], true, "{above}");
    let delayed = pp("1900", "2");
    assert_eq!(delayed["unstable"], true, "{delayed}");
    assert!(delayed["termination"]["operator"].is_object(), "{delayed}");
}

/// Force reflection and the four channels take their gains by name, and
/// say them back (between two two-mass devices, which have load cells);
/// between capstan handles, which have none, a law that reads one is
/// refused by name.
#[test]
fn each_law_reports_its_gains() {
    let between = |law: &str| {
        let line = format!("teleop verify --master {TWO_MASS} --slave {TWO_MASS} {law}");
        line.split_whitespace()
            .map(String::from)
            .collect::<Vec<_>>()
    };
    let args = between("--json position-force --k 500 --b 5 --k-f 0.5 --b-m 3");
    let v = TWOPORT.json(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let g = &v["gains"];
    assert_eq!(
        (g["k_s_npm"].as_f64(), g["c2"].as_f64()),
        (Some(500.0), Some(0.5))
    );
    assert_eq!(g["b_local_nspm"], 3.0);
    assert_eq!(g["k_m_npm"], 0.0);
    let args = between("four-channel --gain k_m_npm=300 --gain k_s_npm=400 --gain c3=1");
    let text = TWOPORT.run(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(
        text.contains("k_m 300 N/m") && text.contains("k_s 400 N/m"),
        "{text}"
    );
    assert!(text.contains("c3 1"), "{text}");
    let args = between_handles("position-force --k 500 --b 5 --k-f 0.5");
    let e = TWOPORT.failure(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(
        e.contains("the slave's load cell") && e.contains("no C_f"),
        "{e}"
    );
}

/// What a lab gets wrong is named: a missing file, devices at two
/// periods, a delay past the longest channel, a negative gain.
#[test]
fn bad_teleoperators_are_named() {
    let dir = support::scratch("teleop");
    let fast = dir.join("fast.toml");
    let text = std::fs::read_to_string(format!("{}/{CAPSTAN}", TWOPORT.root)).unwrap();
    std::fs::write(
        &fast,
        text.replacen("period_s = 0.001", "period_s = 0.0005", 1),
    )
    .unwrap();
    let fast = fast.to_str().unwrap();
    for (line, says) in [
        (
            format!("--master no/such.toml --slave {CAPSTAN} --k 1"),
            "--master no/such.toml",
        ),
        (
            format!("--master {CAPSTAN} --slave {fast} --k 1"),
            "one period",
        ),
        (
            format!("--master {CAPSTAN} --slave {CAPSTAN} --delay 5000 --k 1"),
            "delay 5000 ticks: at most 1024",
        ),
        (
            format!("--master {CAPSTAN} --slave {CAPSTAN} --k -1"),
            "k_m (N/m)",
        ),
    ] {
        // The law's words after the devices', --b 0 for each.
        let line = line.replace(" --k ", " position-position --b 0 --k ");
        let mut args = vec!["teleop", "verify"];
        args.extend(line.split_whitespace());
        let e = TWOPORT.failure(&args);
        assert!(e.contains(says), "{line}: {e}");
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// `teleop <cmd> --json` between two capstan handles, `rest` after.
fn handles_json(cmd: &str, rest: &str) -> serde_json::Value {
    let line = format!("teleop {cmd} --master {CAPSTAN} --slave {CAPSTAN} --json {rest}");
    TWOPORT.json(&line.split_whitespace().collect::<Vec<_>>())
}

/// `teleop design` finds the stiffest position-position coupling the
/// proof allows between two capstan handles: Colgate's `k < b/T` =
/// 2,000 N/m for their relative motion, to 0.1%; and with two ticks of
/// delay and 0.5 N s/m in the law, a stiffness `verify` cannot break
/// there and breaks 2% past.
#[test]
fn design_finds_the_stiffest_proven_coupling() {
    let d = handles_json("design", "position-position --b 0");
    assert_eq!(d["proven"], true, "{d}");
    let k = d["gains"]["k_m_npm"].as_f64().unwrap();
    assert!(k <= 2000.0 && k > 1996.0, "{d}");
    let d = handles_json("design", "--delay 2 position-position --b 0.5");
    let k = d["gains"]["k_m_npm"].as_f64().unwrap();
    let verify = |k: f64| {
        handles_json(
            "verify",
            &format!("--delay 2 position-position --k {k} --b 0.5"),
        )
    };
    assert_eq!(verify(k)["unstable"], false, "{k}");
    assert_eq!(verify(1.02 * k)["unstable"], true, "{k}");
}

/// `teleop check` says proven inside the edge and not past it, and why;
/// a design asked with its gain given, or of four channels, is refused
/// by name.
#[test]
fn check_proves_inside_the_edge_only() {
    let inside = handles_json("check", "position-position --k 1960 --b 0");
    assert_eq!(inside["proven"], true, "{inside}");
    assert!(inside["slack"].as_f64().unwrap() > 0.0, "{inside}");
    let past = handles_json("check", "position-position --k 2040 --b 0");
    assert_eq!(past["proven"], false, "{past}");
    assert!(past["slack"].as_f64().unwrap() < 0.0, "{past}");
    for (law, says) in [
        (
            "position-position --k 100 --b 0",
            "design finds --k: leave it out",
        ),
        (
            "four-channel --gain k_m_npm=100",
            "four-channel: design finds",
        ),
    ] {
        let line = format!("teleop design --master {CAPSTAN} --slave {CAPSTAN} {law}");
        let e = TWOPORT.failure(&line.split_whitespace().collect::<Vec<_>>());
        assert!(e.contains(says), "{law}: {e}");
    }
    for (law, says) in [
        ("position-position --b 0", "give --k"),
        (
            "four-channel --gain k_m=1",
            "no gain `k_m`; the gains are k_m_npm",
        ),
        ("four-channel --gain c2", "--gain c2: give NAME=VALUE"),
    ] {
        let line = format!("teleop check --master {CAPSTAN} --slave {CAPSTAN} {law}");
        let e = TWOPORT.failure(&line.split_whitespace().collect::<Vec<_>>());
        assert!(e.contains(says), "{law}: {e}");
    }
}

/// `--plot` draws what the operator feels through the designed law, and
/// an unwritable path is named.
#[test]
fn design_plots_what_the_operator_feels() {
    let dir = support::scratch("teleop-plot");
    let png = dir.join("felt.png");
    let line = format!(
        "teleop design --master {CAPSTAN} --slave {CAPSTAN} --plot {} position-position --b 0.5",
        png.display()
    );
    TWOPORT.run(&line.split_whitespace().collect::<Vec<_>>());
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let line = format!(
        "teleop check --master {CAPSTAN} --slave {CAPSTAN} --plot /no/such/dir/felt.png position-position --k 100 --b 0"
    );
    let e = TWOPORT.failure(&line.split_whitespace().collect::<Vec<_>>());
    assert!(e.contains("--plot /no/such/dir/felt.png"), "{e}");
    let _ = std::fs::remove_dir_all(dir);
}

/// The wave channel by name: filtered, proven between two capstan
/// handles with one tick of delay; bare, broken (its line resonates at
/// Nyquist); with no delay, or designed with its impedance given,
/// refused by name.
#[test]
fn the_wave_channel_is_proven_filtered_and_broken_bare() {
    let proven = handles_json("check", "--delay 1 wave --b 0.5 --filter-pole 0.9");
    assert_eq!(proven["proven"], true, "{proven}");
    assert_eq!(proven["wave"]["filter_pole"], 0.9f32 as f64, "{proven}");
    let bare = handles_json("verify", "--delay 1 wave --b 0.5");
    assert_eq!(bare["unstable"], true, "{bare}");
    for (cmd, law, says) in [
        (
            "check",
            "wave --b 0.5",
            "delay (ticks) = 0 must be at least 1",
        ),
        (
            "design",
            "--delay 1 wave --b 0.5",
            "design finds --b: leave it out",
        ),
        (
            "check",
            "--delay 1 wave --filter-pole 0.9",
            "wave: give --b",
        ),
        (
            "check",
            "--delay 1 wave --b 0.5 --filter-pole 1",
            "wave filter pole",
        ),
    ] {
        let line = format!("teleop {cmd} --master {CAPSTAN} --slave {CAPSTAN} {law}");
        let e = TWOPORT.failure(&line.split_whitespace().collect::<Vec<_>>());
        assert!(e.contains(says), "{law}: {e}");
    }
}

/// `teleop design wave` finds the largest wave impedance the proof allows
/// at the given filter: proven there and not 5% past it. A lighter
/// filter (its pole lower) proves less impedance, though the operator
/// feels a stiffer wall through it (`b (1 - pole) / T`); the bare
/// channel proves none.
#[test]
fn design_finds_the_largest_proven_wave_impedance() {
    let b_at = |pole: f64| {
        let d = handles_json("design", &format!("--delay 1 wave --filter-pole {pole}"));
        assert_eq!(d["proven"], true, "{d}");
        d["wave"]["b_nspm"].as_f64().unwrap()
    };
    let (light, heavy) = (b_at(0.5), b_at(0.9));
    assert!(light > 0.1 && heavy > light, "{light} then {heavy}");
    let past = handles_json(
        "check",
        &format!("--delay 1 wave --b {} --filter-pole 0.9", 1.05 * heavy),
    );
    assert_eq!(past["proven"], false, "{past}");
    let line = format!("teleop design --master {CAPSTAN} --slave {CAPSTAN} --delay 1 wave");
    let e = TWOPORT.failure(&line.split_whitespace().collect::<Vec<_>>());
    assert!(e.contains("no gain is proven"), "{e}");
}
