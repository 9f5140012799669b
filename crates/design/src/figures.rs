//! The data of the paper's Figs 8-10, from the designer's own results.

use crate::analysis::{
    admittance_coupling_tf, impedance_coupling_tf, impedance_range_admittance,
    impedance_range_impedance, regulator_tf, Analysis,
};
use crate::network::HumanBound;
use crate::plot::{Curve, Figure, LegendAt, RGBColor, BLUE, GREY, RED};
use std::f64::consts::PI;

fn hz(a: &Analysis) -> impl Iterator<Item = f64> + '_ {
    a.points.iter().map(|p| p.omega / (2.0 * PI))
}

fn curve(
    label: String,
    width: u32,
    dashed: bool,
    color: RGBColor,
    a: &Analysis,
    v: Vec<f64>,
) -> Curve {
    Curve {
        label,
        width,
        dashed,
        color,
        points: hz(a).zip(v).collect(),
    }
}

/// Fig. 8: the impedance-display bound on `Re(1/Z_cI)` without (dashed)
/// and with (thin) the human model, and the coupling `(k, b)` (bold).
pub fn fig8(a: &Analysis, k: f64, b: f64) -> Result<Figure, crate::Error> {
    let tf = impedance_coupling_tf(k, b, a.period_s)?;
    let coupling = a.points.iter().map(|p| tf.eval(p.z).inv().re).collect();
    Ok(Figure {
        x_label: "frequency (Hz)".into(),
        legend: LegendAt::LowerRight,
        title: "Fig. 8  Impedance display virtual coupling design".into(),
        y_label: "Re(1/Z_cI)  (m/(N s))".into(),
        curves: vec![
            curve(
                "bound, no human model".into(),
                2,
                true,
                GREY,
                a,
                a.impedance_bound(None),
            ),
            curve(
                "bound, Z_max = 300 + 1000/s".into(),
                1,
                false,
                BLUE,
                a,
                a.impedance_bound(Some(HumanBound::PAPER)),
            ),
            curve(
                format!("coupling k = {k:.0} N/m, b = {b:.0} N s/m"),
                3,
                false,
                RED,
                a,
                coupling,
            ),
        ],
    })
}

/// Fig. 9: the admittance-display bound on `Re Z_cA` for the regulator
/// `(kp, bp)` without (dashed) and with (thin) the human model, and the
/// coupling `(m, b)` (bold).
pub fn fig9(
    a: &Analysis,
    (kp, bp): (f64, f64),
    (m, b): (f64, f64),
) -> Result<Figure, crate::Error> {
    let k = regulator_tf(kp, bp, a.period_s)?;
    let tf = admittance_coupling_tf(m, b, a.period_s)?;
    let coupling = a.points.iter().map(|p| tf.eval(p.z).re).collect();
    Ok(Figure {
        x_label: "frequency (Hz)".into(),
        legend: LegendAt::LowerRight,
        title: format!("Fig. 9  Admittance display virtual coupling design (K_p = {kp:.0} + {bp:.0}(1 - 1/z)/T)"),
        y_label: "Re Z_cA  (N s/m)".into(),
        curves: vec![
            curve("bound, no human model".into(), 2, true, GREY, a, a.admittance_bound(&k, None)),
            curve(
                "bound, Z_max = 300 + 1000/s".into(),
                1,
                false,
                BLUE,
                a,
                a.admittance_bound(&k, Some(HumanBound::PAPER)),
            ),
            curve(format!("coupling m = {m:.2} kg, b = {b:.0} N s/m"), 3, false, RED, a, coupling),
        ],
    })
}

/// Fig. 10: `|Z_min|` and `|Z_max|` of both displays (thin: impedance
/// display `(k, b)`; bold: admittance display `(kp, bp)`, `(m, b_a)`).
pub fn fig10(
    a: &Analysis,
    (k, b): (f64, f64),
    kp: (f64, f64),
    (m, ba): (f64, f64),
) -> Result<Figure, crate::Error> {
    let imp = impedance_range_impedance(a, k, b)
        .ok_or(crate::Error::Figure("invalid impedance coupling".into()))?;
    let adm = impedance_range_admittance(a, kp, (m, ba))
        .ok_or(crate::Error::Figure("invalid admittance coupling".into()))?;
    let mag = |r: &[(num_complex::Complex64, num_complex::Complex64)], hi: bool| -> Vec<f64> {
        r.iter()
            .map(|(lo, up)| if hi { up.norm() } else { lo.norm() })
            .collect()
    };
    Ok(Figure {
        x_label: "frequency (Hz)".into(),
        legend: LegendAt::LowerRight,
        title: "Fig. 10  Impedance range (thin: impedance display, bold: admittance display; the Z_max coincide, eq 29)".into(),
        y_label: "|Z|  (N s/m)".into(),
        curves: vec![
            curve("impedance display Z_max".into(), 1, false, BLUE, a, mag(&imp, true)),
            curve("impedance display Z_min".into(), 1, true, BLUE, a, mag(&imp, false)),
            curve("admittance display Z_max".into(), 3, false, RED, a, mag(&adm, true)),
            curve("admittance display Z_min".into(), 3, true, RED, a, mag(&adm, false)),
        ],
    })
}
