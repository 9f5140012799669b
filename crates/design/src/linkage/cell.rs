//! Bounds on a linkage's Cartesian damping and mass over a box of joint
//! angles, rigorous: every pose in the box (inside the relative limits)
//! has eigenvalues within them.
//!
//! Both matrices are taken through their inverses, which need no inverse
//! Jacobian: `D_x^-1 = J D_q^-1 J^T` and `M_x^-1 = J M_q^-1 J^T`. For
//! either, call it `A(q)`, the box's centre `c` and half-widths `h`:
//!
//! - Taylor's theorem with the Lagrange remainder gives
//!   `A(c + Δ) = A(c) + Σ_k ∂_k A(c) Δ_k + R(Δ)`, where each entry of `R`
//!   is at most `½ Σ_kl |∂_kl A|_box h_k h_l`, the Hessian enclosed over
//!   the whole box by [`Taylor`] arithmetic on the board's own kinematics.
//! - The affine part `L(Δ)` is a symmetric matrix affine in `Δ`, so its
//!   largest eigenvalue is convex in `Δ` and its least concave: both take
//!   their extremes over the feasible set (the box cut by the relative
//!   limits, a polytope) at its vertices.
//! - Weyl's inequality moves each eigenvalue by at most `‖R‖₂`, which is at
//!   most the largest row sum of the entrywise bound.
//!
//! So `λ_max(A) ≤ max_v λ_max(L(v)) + ‖R‖` and `λ_min(A) ≥ min_v
//! λ_min(L(v)) - ‖R‖`, with an allowance for the eigen-solver's rounding.
//! The remainder is second order in the box's size, so halving a box near
//! the least damped pose quarters the gap.

use super::file::{Inertia, LinkageFile, OnKinematics};
use super::interval::Interval;
use super::taylor::Taylor;
use nalgebra::{DMatrix, DVector};
use twoport_control::kinematics::Kinematics;
use twoport_control::Real;

/// The eigenvalue bounds over a box.
#[derive(Clone, Debug, PartialEq)]
pub struct CellBounds {
    /// `(λ_min lower bound, λ_max upper bound)` of `D_x` (N s/m); the
    /// upper end is `∞` where the box may reach a pose that sees no
    /// damping in some direction.
    pub damping_nspm: (f64, f64),
    /// The same for `M_x` (kg).
    pub mass_kg: (f64, f64),
    /// The feasible vertex at which the damping's bound binds (rad): where
    /// to look for the box's least damped pose.
    pub least_damped_q_rad: Vec<f64>,
    /// The joint whose side adds most to the bounds' looseness: the one
    /// to split.
    pub split: usize,
}

/// Why a box has no bounds: no pose in it is driven.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Undecided {
    /// The box lies wholly outside the relative limits.
    Infeasible,
    /// The kinematics refuse every pose in the box (past a singularity's
    /// floor, or unreachable): the board drives none of them.
    Refused,
}

/// Joint-space quantities in the Taylor scalar over a box.
type Mat<const N: usize> = [[Taylor<N>; N]; N];

/// `J X^-1 J^T` for a symmetric positive definite `X` (Gauss-Jordan; the
/// pivot order is chosen on midpoints, which only decides tightness).
fn congruence<const N: usize>(j: &Mat<N>, x: &Mat<N>) -> Option<Mat<N>> {
    // Solve X Y = J^T for Y = X^-1 J^T.
    let mut a = *x;
    let mut y: Mat<N> = core::array::from_fn(|r| core::array::from_fn(|c| j[c][r]));
    for col in 0..N {
        let p = (col..N).max_by(|&r, &s| {
            a[r][col]
                .v
                .mag()
                .partial_cmp(&a[s][col].v.mag())
                .unwrap_or(std::cmp::Ordering::Equal)
        })?;
        a.swap(col, p);
        y.swap(col, p);
        let pivot = a[col][col];
        if pivot.v.contains_zero() {
            return None;
        }
        for k in 0..N {
            a[col][k] = a[col][k] / pivot;
            y[col][k] = y[col][k] / pivot;
        }
        for r in 0..N {
            if r == col {
                continue;
            }
            let f = a[r][col];
            for k in 0..N {
                a[r][k] = a[r][k] - f * a[col][k];
                y[r][k] = y[r][k] - f * y[col][k];
            }
        }
    }
    Some(core::array::from_fn(|r| {
        core::array::from_fn(|c| {
            let mut s = Taylor::ZERO;
            for k in 0..N {
                s += j[r][k] * y[k][c];
            }
            s
        })
    }))
}

/// `M_q` over the box given `J` there.
fn joint_mass<const N: usize>(file: &LinkageFile, j: &Mat<N>, q: &[Taylor<N>; N]) -> Mat<N> {
    let c = |x: f64| Taylor::<N>::from(x);
    let rotor = |i: usize| c(file.motors.ratios[i].powi(2) * file.motors.rotor_inertia_kgm2);
    let m: Mat<N> = match (&file.inertia, file.geometry) {
        (
            Inertia::Lumped {
                handle_mass_kg,
                link_inertia_kgm2,
            },
            _,
        ) => core::array::from_fn(|r| {
            core::array::from_fn(|col| {
                let mut s = Taylor::ZERO;
                for row in j {
                    s += row[r] * row[col];
                }
                let diag = if r == col {
                    c(link_inertia_kgm2[r]) + rotor(r)
                } else {
                    Taylor::ZERO
                };
                diag + s * c(*handle_mass_kg)
            })
        }),
        (Inertia::SerialArmLinks { .. }, _) if N == 3 => match file.serial_arm_dynamics() {
            Some(arm) => {
                let m = arm.joint_mass_in([q[0], q[1], q[2]]);
                core::array::from_fn(|r| core::array::from_fn(|col| m[r][col]))
            }
            None => core::array::from_fn(|r| {
                core::array::from_fn(|col| if r == col { rotor(r) } else { Taylor::ZERO })
            }),
        },
        _ => core::array::from_fn(|r| {
            core::array::from_fn(|col| if r == col { rotor(r) } else { Taylor::ZERO })
        }),
    };
    m
}

/// The inverse Cartesian damping and mass, `J D_q^-1 J^T` and
/// `J M_q^-1 J^T`, over the box `q`; `None` for the damping where a joint
/// has none (then `D_x` is singular at every pose), and for either where
/// the box is too wide to bound it; `Refused` where the kinematics refuse
/// every pose in the box.
#[allow(clippy::type_complexity)]
fn inverses<K: Kinematics<Taylor<N>, N>, const N: usize>(
    file: &LinkageFile,
    k: &K,
    q: &[Taylor<N>; N],
    mass: bool,
) -> Result<(Option<Mat<N>>, Option<Mat<N>>), Undecided> {
    let j = k.forward(q).map_err(|_| Undecided::Refused)?.jacobian;
    let b = &file.joints.damping_nmsprad;
    // `D_q` is diagonal: `J D_q^-1 J^T = Σ_k J_:k J_:k^T / b_k`.
    let d = b.iter().all(|&b| b > 0.0).then(|| {
        let mut out: Mat<N> = [[Taylor::ZERO; N]; N];
        for r in 0..N {
            for c in r..N {
                let mut s = Taylor::ZERO;
                for (k, &b) in b.iter().enumerate() {
                    let inv = Taylor::constant(Interval::point(b).recip());
                    s += j[r][k] * j[c][k] * inv;
                }
                (out[r][c], out[c][r]) = (s, s);
            }
        }
        out
    });
    // (A pivot the box cannot keep from zero leaves that matrix unbounded
    // here, `None`, and the box is split: its poses are still driven.)
    let m = if mass {
        congruence(&j, &joint_mass(file, &j, q))
    } else {
        None
    };
    Ok((d, m))
}

/// The vertices of `{Δ : |Δ_k| ≤ h_k} ∩ {relative limits}` about the
/// centre `c`: the box's corners where no relative limit cuts it, else
/// every intersection of `N` of the constraints' planes that meets all of
/// them.
fn vertices(file: &LinkageFile, c: &[f64], h: &[f64]) -> Vec<Vec<f64>> {
    let n = c.len();
    // Rows `a Δ <= b`.
    let mut rows: Vec<(Vec<f64>, f64)> = Vec::new();
    for k in 0..n {
        let mut e = vec![0.0; n];
        e[k] = 1.0;
        rows.push((e.clone(), h[k]));
        rows.push((e.iter().map(|x| -x).collect(), h[k]));
    }
    let mut cut = false;
    for r in &file.joints.relative {
        let [i, j] = r.joints;
        let mid = c[j] - c[i];
        let (lo, hi) = (mid - h[i] - h[j], mid + h[i] + h[j]);
        if hi < r.rad[0] || lo > r.rad[1] {
            return Vec::new();
        }
        if lo < r.rad[0] || hi > r.rad[1] {
            cut = true;
            let mut a = vec![0.0; n];
            a[j] = 1.0;
            a[i] = -1.0;
            rows.push((a.clone(), r.rad[1] - mid));
            rows.push((a.iter().map(|x| -x).collect(), mid - r.rad[0]));
        }
    }
    if !cut {
        return (0..1usize << n)
            .map(|bits| {
                (0..n)
                    .map(|k| if bits >> k & 1 == 1 { h[k] } else { -h[k] })
                    .collect()
            })
            .collect();
    }
    let scale = h.iter().fold(0.0f64, |a, &b| a.max(b)).max(1e-300);
    let mut out: Vec<Vec<f64>> = Vec::new();
    let m = rows.len();
    let mut pick: Vec<usize> = (0..n).collect();
    loop {
        let a = DMatrix::from_fn(n, n, |r, k| rows[pick[r]].0[k]);
        let b = DVector::from_fn(n, |r, _| rows[pick[r]].1);
        if let Some(x) = a.lu().solve(&b) {
            let ok = rows.iter().all(|(a, b)| {
                let lhs: f64 = a.iter().zip(x.iter()).map(|(a, x)| a * x).sum();
                lhs <= b + 1e-9 * scale
            });
            if ok && x.iter().all(|v| v.is_finite()) {
                out.push(x.iter().copied().collect());
            }
        }
        // The next combination of n rows out of m.
        let mut i = n;
        loop {
            if i == 0 {
                return out;
            }
            i -= 1;
            if pick[i] < m - n + i {
                break;
            }
        }
        pick[i] += 1;
        for k in i + 1..n {
            pick[k] = pick[k - 1] + 1;
        }
    }
}

/// The extreme eigenvalues of a symmetric `A(c + Δ)` over the feasible
/// vertices `vs` given its entries' enclosures (their value and gradient
/// at the centre, their Hessian over the box): `(λ_min lower bound, λ_max upper bound, the vertex where
/// λ_max binds)`.
fn eigen_bounds<const N: usize>(
    a: &Mat<N>,
    h: &[f64],
    vs: &[Vec<f64>],
) -> (f64, f64, usize, [f64; N]) {
    // The remainder's entrywise bound, and the centre's own rounding; and
    // each joint's share of it.
    let mut rad = [[0.0f64; N]; N];
    let mut share = [0.0f64; N];
    for r in 0..N {
        for c in 0..N {
            let e = &a[r][c];
            let mut s = 0.5 * (e.vc.hi - e.vc.lo);
            for k in 0..N {
                s += 0.5 * (e.gc[k].hi - e.gc[k].lo) * h[k];
                for l in 0..N {
                    let x = 0.5 * e.h[k][l].mag() * h[k] * h[l];
                    s += x;
                    share[k] += x;
                }
            }
            rad[r][c] = s;
        }
    }
    // ‖R‖₂ ≤ max row sum of the symmetric entrywise bound (rounded up:
    // the relative 1e-12 covers the sums' rounding many times over).
    // (An unbounded or NaN entry, from a box that reaches where the
    // kinematics blow up, bounds nothing: f64::max would pass a NaN over.)
    if rad.iter().flatten().any(|x| !x.is_finite()) {
        return (f64::NEG_INFINITY, f64::INFINITY, 0, [f64::INFINITY; N]);
    }
    let norm = (0..N)
        .map(|r| (0..N).map(|c| rad[r][c].max(rad[c][r])).sum::<f64>())
        .fold(0.0f64, f64::max)
        * (1.0 + 1e-12);
    let (mut lo, mut hi, mut at_hi) = (f64::INFINITY, f64::NEG_INFINITY, 0);
    for (i, v) in vs.iter().enumerate() {
        // The affine part at the vertex, symmetrised.
        let l = DMatrix::from_fn(N, N, |r, c| {
            let (a, b) = (&a[r][c], &a[c][r]);
            let slope = a.gc.iter().zip(&b.gc).zip(v);
            0.5 * (a.vc.mid() + b.vc.mid())
                + slope
                    .map(|((ga, gb), dv)| 0.5 * (ga.mid() + gb.mid()) * dv)
                    .sum::<f64>()
        });
        if l.iter().any(|x| !x.is_finite()) {
            return (f64::NEG_INFINITY, f64::INFINITY, 0, [f64::INFINITY; N]);
        }
        // The symmetric eigen-solver is backward stable: its eigenvalues
        // are within a few ε‖L‖ of the exact ones; 1e-12 ‖L‖_F is ample.
        let slack = 1e-12 * l.norm();
        let e = l.symmetric_eigenvalues();
        lo = lo.min(e.min() - slack);
        if e.max() + slack > hi {
            (hi, at_hi) = (e.max() + slack, i);
        }
    }
    (lo - norm, hi + norm, at_hi, share)
}

/// Bound one box `[lo, hi]` of joint angles.
struct Bound<'a> {
    file: &'a LinkageFile,
    lo: &'a [f64],
    hi: &'a [f64],
    mass: bool,
}

impl OnKinematics for Bound<'_> {
    type Out = Result<CellBounds, Undecided>;
    fn run<K, const N: usize>(self, k: K) -> Self::Out
    where
        K: Kinematics<f64, N> + Kinematics<Taylor<N>, N>,
    {
        let c: Vec<f64> = (0..N)
            .map(|i| 0.5 * self.lo[i] + 0.5 * self.hi[i])
            .collect();
        // Half-widths, rounded up so that [c - h, c + h] holds the box (a
        // joint the search holds fixed keeps none).
        let h: Vec<f64> = (0..N)
            .map(|i| match (self.hi[i] - c[i]).max(c[i] - self.lo[i]) {
                0.0 if self.lo[i] == self.hi[i] => 0.0,
                h => h.next_up(),
            })
            .collect();
        let vs = vertices(self.file, &c, &h);
        if vs.is_empty() {
            return Err(Undecided::Infeasible);
        }
        let q: [Taylor<N>; N] = core::array::from_fn(|i| Taylor::variable(i, c[i], h[i]));
        let (d, m) = inverses(self.file, &k, &q, self.mass)?;
        // 1/x rounded toward the bound's side.
        let inv = |x: f64| if x > 0.0 { 1.0 / x } else { f64::INFINITY };
        let bounds = |lo: f64, hi: f64| (inv(hi).next_down().max(0.0), inv(lo).next_up());
        let mut share = [0.0; N];
        let (damping_nspm, vertex) = match d {
            Some(d) => {
                let (lo, hi, v, s) = eigen_bounds(&d, &h, &vs);
                share = s;
                (bounds(lo, hi), v)
            }
            None => ((0.0, f64::INFINITY), 0),
        };
        let mass_kg = match m {
            Some(m) => {
                let (lo, hi, _, s) = eigen_bounds(&m, &h, &vs);
                if share.iter().all(|&x| x == 0.0) {
                    share = s;
                }
                bounds(lo, hi)
            }
            None => (0.0, f64::INFINITY),
        };
        // (A box with no remainder, or an unbounded one, splits its widest
        // side.)
        let measured = share.iter().all(|x| x.is_finite()) && share.iter().any(|&x| x > 0.0);
        let weight = |i: usize| if measured { share[i] } else { h[i] };
        Ok(CellBounds {
            damping_nspm,
            mass_kg,
            least_damped_q_rad: (0..N).map(|i| c[i] + vs[vertex][i]).collect(),
            split: (0..N)
                .max_by(|&a, &b| weight(a).total_cmp(&weight(b)))
                .unwrap_or(0),
        })
    }
}

impl LinkageFile {
    /// Rigorous bounds on the Cartesian damping's eigenvalues, and the
    /// mass's if `mass` (else `(0, ∞)`), over the box of joint angles
    /// `[lo, hi]` (rad), cut by the file's relative limits.
    pub fn cell_bounds(&self, lo: &[f64], hi: &[f64], mass: bool) -> Result<CellBounds, Undecided> {
        self.geometry
            .on_kinematics(Bound {
                file: self,
                lo,
                hi,
                mass,
            })
            .unwrap_or(Err(Undecided::Refused))
    }
}

#[cfg(test)]
mod tests {
    use crate::linkage::test_files::{shipped, SHIPPED};

    /// Every pose sampled inside a box has its damping's and mass's
    /// eigenvalues within the box's bounds, for boxes of several sizes
    /// about poses of each shipped linkage (inside its joint limits, as
    /// the search's boxes are), and the bounds close on the pose's values
    /// as the box shrinks (second order: a tenth the size, about a
    /// hundredth the gap).
    #[test]
    fn a_box_holds_every_pose_in_it() {
        for name in SHIPPED {
            let file = shipped(name);
            let poses = file.workspace(4);
            for p in poses.iter().step_by(3) {
                let mut gaps = Vec::new();
                for w in [0.1, 0.01] {
                    let limits = &file.joints.limits_rad;
                    let lo: Vec<f64> = p
                        .q_rad
                        .iter()
                        .zip(limits)
                        .map(|(q, l)| (q - w).max(l[0]))
                        .collect();
                    let hi: Vec<f64> = p
                        .q_rad
                        .iter()
                        .zip(limits)
                        .map(|(q, l)| (q + w).min(l[1]))
                        .collect();
                    let Ok(b) = file.cell_bounds(&lo, &hi, true) else {
                        continue;
                    };
                    let n = lo.len();
                    for s in 0..3usize.pow(n as u32) {
                        let q: Vec<f64> = (0..n)
                            .map(|k| {
                                let step = (s / 3usize.pow(k as u32) % 3) as f64;
                                lo[k] + 0.5 * (hi[k] - lo[k]) * step
                            })
                            .collect();
                        if !file.within_limits(&q) {
                            continue;
                        }
                        let Ok(at) = file.pose(&q) else { continue };
                        let d = at.damping_nspm.clone().symmetric_eigenvalues();
                        let m = at.mass_kg.clone().symmetric_eigenvalues();
                        let tol = |x: f64| 1e-9 * x.abs();
                        assert!(d.min() >= b.damping_nspm.0 - tol(d.min()), "{name} {q:?}");
                        assert!(d.max() <= b.damping_nspm.1 + tol(d.max()), "{name} {q:?}");
                        assert!(m.min() >= b.mass_kg.0 - tol(m.min()), "{name} {q:?}");
                        assert!(m.max() <= b.mass_kg.1 + tol(m.max()), "{name} {q:?}");
                    }
                    let at = p.damping_nspm.clone().symmetric_eigenvalues().min();
                    gaps.push((at - b.damping_nspm.0) / at);
                }
                if let [wide, narrow] = gaps[..] {
                    assert!(
                        narrow < 0.2 * wide + 1e-9,
                        "{name} at {:?}: gap {wide} then {narrow}",
                        p.q_rad
                    );
                }
            }
        }
    }
}
