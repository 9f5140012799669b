//! Teleoperation in the simulator: two devices, each with its plant and
//! effects, through the control crate's teleoperator. The designer's
//! proven gains hold here, on every pair and architecture, and the pair
//! grows 20% past the proof.

use host_sim::engine::teleop::{TeleopReport, TeleopSample, TeleopScene, Teleoperation};
use std::path::{Path, PathBuf};
use twoport_control::teleop::FourChannelGains;
use twoport_design::designer::TeleopDesigner;
use twoport_design::verify::{TeleopLaw, WaveGains};
use twoport_design::DeviceModel;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A scene's model paths taken from the repository's root.
fn rooted(mut s: TeleopScene) -> TeleopScene {
    for side in [&mut s.master, &mut s.slave] {
        side.plant.model = root().join(&side.plant.model);
    }
    s
}

fn run(scene: TeleopScene) -> (TeleopReport, Vec<TeleopSample>) {
    let mut t = Teleoperation::new(scene).unwrap();
    let mut kept = Vec::new();
    let report = t.run(|s| kept.push(*s));
    (report, kept)
}

/// The largest master-slave stretch over `samples` (m).
fn stretch(samples: &[TeleopSample]) -> f64 {
    samples
        .iter()
        .map(|s| (s.master.handle_m[0] - s.slave.handle_m[0]).abs())
        .fold(0.0, f64::max)
}

/// The rigid 0.1 kg, 1 N s/m device of `scenes/teleop/rigid_pair.toml`,
/// as the designer takes it.
fn rigid() -> DeviceModel {
    DeviceModel::from_toml(
        "period_s = 0.001\npeak_force_n = 50.0\ncontinuous_force_n = 20.0\n\
         M = [[0.1]]\nD = [[1.0]]\nK = [[0.0]]\nG = [[1.0, -1.0]]\nC_v = [[1.0], [-1.0]]\n",
        "rigid",
    )
    .unwrap()
}

#[test]
fn a_delayed_channel_holds_at_the_proven_gain_and_grows_20_percent_past() {
    let designer = TeleopDesigner::new(&rigid(), &rigid(), 1, None).unwrap();
    let (k, _) = designer
        .largest(|k| FourChannelGains::position_position(k as f32, 0.0), 1e5)
        .unwrap()
        .expect("a proven spring");
    assert!((k - 499.2).abs() < 1.0, "proven to {k} N/m");
    let at = |k: f64| {
        let sets = [
            format!("law.gains.k_m_npm={k}"),
            format!("law.gains.k_s_npm={k}"),
        ];
        let s = TeleopScene::load(&root().join("scenes/teleop/rigid_pair.toml"), &sets).unwrap();
        run(s)
    };
    // At the proven spring the tap's ringing dies away: the last second's
    // stretch is below the first's.
    let (report, samples) = at(k);
    assert!(report.stable, "{:?}", report.reason);
    let first = stretch(&samples[..1_000]);
    let last = stretch(&samples[samples.len() - 1_000..]);
    assert!(last < first, "stretch {first} m then {last} m");
    // 20% past, the same tap grows without bound.
    let (report, samples) = at(1.2 * k);
    assert!(!report.stable);
    let last = stretch(&samples[samples.len() - 1_000..]);
    assert!(last > 100.0 * first, "stretch {first} m then {last} m");
}

/// The operator grips the master, moves the slave onto a stiff wall at
/// 5 mm, presses, shakes and lets go; the slave's own hand is off.
fn wall_scene(master: &str, slave: &str, law: TeleopLaw, delay: usize) -> TeleopScene {
    let side = |model: &str, wall: bool| {
        let mut s = format!(
            "[plant]\nmodel = \"{}\"\n[effects]\nflexibility = true\nload_cell = {}\n\
             encoder = {{ resolution_m = 1.0e-6, bits = 16 }}\nsaturation = {{ limit_n = 20.0 }}\n",
            root().join(model).display(),
            DeviceModel::load(&root().join(model)).unwrap().force_sensor
        );
        if wall {
            s += "hard_stop = { position_m = 0.005, solid = \"above\", stiffness_npm = 1.0e5, on = \"handle\" }\n";
        }
        s.parse::<toml::Table>().unwrap()
    };
    let mut master_side = side(master, false);
    master_side.insert(
        "human".into(),
        toml::from_str::<toml::Table>(
            "grasp = \"relaxed\"\nscript = [\n\
             { kind = \"move\", at_s = 0.2, to_m = 0.008, over_s = 0.8 },\n\
             { kind = \"shake\", at_s = 1.5, amplitude_m = 0.001, frequency_hz = 4.0, for_s = 1.0 },\n\
             { kind = \"move\", at_s = 3.0, to_m = 0.0, over_s = 0.5 },\n\
             { kind = \"grip\", at_s = 4.0, grasp = \"hands_off\" },\n]\n",
        )
        .unwrap()
        .into(),
    );
    let mut t = toml::Table::new();
    t.insert("name".into(), format!("{master} to {slave}").into());
    t.insert("duration_s".into(), 6.0.into());
    t.insert("law".into(), toml::Value::try_from(law).unwrap());
    t.insert(
        "channel".into(),
        toml::from_str::<toml::Table>(&format!("delay_ticks = {delay}"))
            .unwrap()
            .into(),
    );
    t.insert("master".into(), master_side.into());
    t.insert("slave".into(), side(slave, true).into());
    TeleopScene::parse(&toml::to_string(&t).unwrap(), "generated", &[]).unwrap()
}

/// Each architecture the pair's sensors allow, at 80% of the largest
/// gain the designer proves: position-position's spring, force
/// reflection's scale, four channels' force channels on half the proven
/// spring, and the filtered wave channel. The name, and the law.
fn proven_laws(
    master: &DeviceModel,
    slave: &DeviceModel,
    delay: usize,
) -> Vec<(String, TeleopLaw)> {
    let designer = TeleopDesigner::new(master, slave, delay, None).unwrap();
    let largest = |gains: &dyn Fn(f64) -> FourChannelGains, max: f64| {
        designer
            .largest(gains, max)
            .unwrap()
            .expect("a proven gain")
            .0
    };
    let pp = |k: f64| FourChannelGains::position_position(k as f32, 0.5);
    let k = largest(&pp, 1e5);
    let mut laws = vec![(
        format!("position-position k = {:.0} N/m", 0.8 * k),
        TeleopLaw::FourChannel(pp(0.8 * k)),
    )];
    if slave.force_sensor {
        let pf =
            |k_f: f64| FourChannelGains::position_force((0.5 * k) as f32, 0.5, k_f as f32, 0.5);
        let k_f = largest(&pf, 4.0);
        laws.push((
            format!("force reflection k_f = {:.4}", 0.8 * k_f),
            TeleopLaw::FourChannel(pf(0.8 * k_f)),
        ));
    }
    if slave.force_sensor && master.force_sensor {
        let four = |c: f64| FourChannelGains {
            c2: c as f32,
            c3: c as f32,
            ..pp(0.5 * k)
        };
        let c = largest(&four, 4.0);
        laws.push((
            format!("four channels c = {:.4}", 0.8 * c),
            TeleopLaw::FourChannel(four(0.8 * c)),
        ));
    }
    let wave = TeleopLaw::Wave(WaveGains {
        b_nspm: 0.5,
        filter_pole: 0.9,
    });
    let proof = designer.check_law(wave).unwrap();
    assert!(proof.check.proven, "the filtered wave channel");
    laws.push(("wave b = 0.5 N s/m, filter 0.9".into(), wave));
    laws
}

#[test]
fn every_architecture_holds_at_its_proven_gains_on_four_pairs() {
    let pairs = [
        ("models/capstan.toml", "models/capstan.toml"),
        ("models/two_mass.toml", "models/two_mass.toml"),
        ("models/excalibur.toml", "models/two_mass.toml"),
        ("models/two_mass.toml", "models/excalibur.toml"),
    ];
    let mut architectures = std::collections::BTreeSet::new();
    for (m, s) in pairs {
        let load = |p: &str| DeviceModel::load(&root().join(p)).unwrap();
        for delay in [1, 3] {
            for (name, law) in proven_laws(&load(m), &load(s), delay) {
                let (report, samples) = run(wall_scene(m, s, law, delay));
                let case = format!("{m} to {s}, {delay} ticks, {name}");
                assert!(report.stable, "{case}: {:?}", report.reason);
                // The slave reached the wall and the pair came to rest
                // together.
                let slave_max = samples
                    .iter()
                    .map(|s| s.slave.handle_m[0])
                    .fold(0.0, f64::max);
                assert!(slave_max > 0.004, "{case}: the slave reached {slave_max} m");
                assert!(
                    report.late_error_m < 1e-3,
                    "{case}: {} m apart",
                    report.late_error_m
                );
                architectures.insert(name.split(' ').next().unwrap().to_string());
            }
        }
    }
    assert_eq!(architectures.len(), 4, "{architectures:?}");
}

#[test]
fn the_shipped_scenes_run_their_proven_gains() {
    for name in ["capstan_wall", "two_mass_force", "excalibur_wave"] {
        let path = root().join(format!("scenes/teleop/{name}.toml"));
        let scene = rooted(TeleopScene::load(&path, &[]).unwrap());
        let model = |p: &Path| DeviceModel::load(p).unwrap();
        let designer = TeleopDesigner::new(
            &model(&scene.master.plant.model),
            &model(&scene.slave.plant.model),
            scene.channel.delay_ticks,
            None,
        )
        .unwrap();
        let proof = designer.check_law(scene.law).unwrap();
        assert!(proof.check.proven, "{name}: {:?}", proof.check);
        let (report, _) = run(scene);
        assert!(report.stable, "{name}: {:?}", report.reason);
    }
}

#[test]
fn a_jittery_channel_needs_its_guard() {
    let path = root().join("scenes/teleop/rigid_pair.toml");
    let with = |sets: &[&str]| {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        run(TeleopScene::load(&path, &sets).unwrap())
    };
    // Proven for one tick, run across a channel of one to five.
    let jitter = ["channel.jitter_ticks=4", "duration_s=10"];
    let (bare, _) = with(&jitter);
    assert!(!bare.stable, "the jittery channel held without a guard");
    let guarded = [
        jitter[0],
        jitter[1],
        "channel.guard.mass_kg=0.1",
        "channel.guard.force_limit_n=20",
    ];
    let (report, samples) = with(&guarded);
    assert!(report.stable, "{:?}", report.reason);
    assert!(samples
        .iter()
        .any(|s| s.guard_nspm.iter().any(|&b| b > 0.0)));
}

#[test]
fn a_scene_the_teleoperator_cannot_run_is_refused_by_name() {
    let base = std::fs::read_to_string(root().join("scenes/teleop/rigid_pair.toml")).unwrap();
    let refused = |sets: &[&str]| {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        TeleopScene::parse(&base, "rigid_pair.toml", &sets)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    };
    let force = refused(&["law.gains.c2=0.1"]);
    assert!(force.contains("slave's load cell"), "{force}");
    let wave = refused(&["law={ wave = { b_nspm = 0.5 } }", "channel.jitter_ticks=2"]);
    assert!(wave.contains("channel: the wave channel"), "{wave}");
    let drop = refused(&["channel.drop_fraction=1.5"]);
    assert!(drop.contains("channel.drop_fraction"), "{drop}");
    let linkage = refused(&["slave.plant.linkage=\"models/linkages/hapkit.toml\""]);
    assert!(linkage.contains("slave.plant.linkage"), "{linkage}");
    let mass = refused(&["master.plant.rigid_mass_kg=-1"]);
    assert!(mass.contains("master: plant.rigid_mass_kg"), "{mass}");
    let typo = refused(&["law.gains.k_q=1"]);
    assert!(typo.contains("k_q"), "{typo}");
}

#[test]
fn a_pair_of_boards_runs_the_law_the_designer_proves() {
    use host_sim::link::{LinkFaults, LocalBoard};
    use host_sim::pil::teleop::run_pair;
    use twoport_control::teleop::FourChannel;
    use twoport_control::Position;
    let path = root().join("scenes/pil/teleop_pair.toml");
    let scene = rooted(TeleopScene::load(&path, &[]).unwrap());
    let ticks = 4_000;
    let boards = || LocalBoard::excalibur().unwrap();
    let pair = run_pair(&scene, ticks, [boards(), boards()], LinkFaults::default()).unwrap();
    // Each board's coupling against the host's held point is the
    // position-position law across the host's two ticks: stepped on what
    // the boards read, the law gives each board's force to its
    // amplifier's resolution.
    let TeleopLaw::FourChannel(gains) = scene.law else {
        panic!("a four-channel law")
    };
    let mut law = FourChannel::<f32, 8>::new(gains, 1e-3, 2, Position::ZERO).unwrap();
    let read = |i: usize, t: usize| Position::from_nm((pair.read_pm[i][t] / 1000) as i32);
    let motion = |i: usize, t: usize| {
        let before = read(i, t.saturating_sub(1));
        (read(i, t), read(i, t).nm_from::<f32>(before) * 1e-9 / 1e-3)
    };
    let lsb_n = 200.0 / 32_767.0;
    let mut worst = 0.0f64;
    let mut peak = 0.0f64;
    for t in 0..ticks as usize {
        let f = law.step(motion(0, t), motion(1, t), 0.0, 0.0);
        let armed = t as u64 >= pair.runs[0].armed_at_tick;
        for (run, want) in pair.runs.iter().zip([f.master_n, f.slave_n]) {
            let got = run.samples[t].actuator_n[0];
            let want = if armed { f64::from(want) } else { 0.0 };
            worst = worst.max((got - want).abs());
            peak = peak.max(got.abs());
        }
    }
    assert!(peak > 1.0, "the slave pressed the wall: {peak} N");
    assert!(
        worst <= lsb_n,
        "{worst} N from the law (one step {lsb_n} N)"
    );
}
