//! The classic friction models, fitted with the same optimiser on the same
//! data: the honest comparison.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | F_c | Coulomb level | N |
//! | F_s | static (breakaway) level | N |
//! | v_s | Stribeck velocity | m/s |
//! | b = σ₂ | viscous coefficient | N·s/m |
//! | σ₀ | bristle stiffness | N/m |
//! | σ₁ | bristle damping | N·s/m |
//! | z | mean bristle deflection | m |
//!
//! - Coulomb + viscous: F = F_c sgn v + b v
//! - Stribeck: F = g(v) sgn v + b v, g(v) = F_c + (F_s − F_c) e^{−(v/v_s)²}
//! - LuGre: ż = v − σ₀ |v| z / g(v), F = σ₀ z + σ₁ ż + σ₂ v
//!
//! How the levels follow the normal load N ([`LoadForm`]): constant; linear
//! (F_c = F_c0 + μ_c N, F_s = F_s0 + μ_s N), the classic models' usual
//! extension and what keeps the comparison fair when the data span several
//! loads; or proportional (F_c = μ_c N, F_s = μ_s N), the one form that can
//! carry a fit at a single load to another load. LuGre's bristle
//! state is integrated exactly over each sample interval for the velocity
//! at its end (ż = v − a z is linear in z), so it is stable for any σ₀;
//! it starts in its steady state. On a steady curve LuGre is Stribeck.

use super::params::{DataScale, Parameter};
use super::problem::Model;
use super::series::Series;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BaselineKind {
    CoulombViscous,
    Stribeck,
    LuGre,
}

impl BaselineKind {
    pub const ALL: [BaselineKind; 3] = [
        BaselineKind::CoulombViscous,
        BaselineKind::Stribeck,
        BaselineKind::LuGre,
    ];

    pub fn label(self) -> &'static str {
        match self {
            BaselineKind::CoulombViscous => "Coulomb + viscous",
            BaselineKind::Stribeck => "Stribeck",
            BaselineKind::LuGre => "LuGre",
        }
    }
}

/// How a classic model's friction levels follow the normal load.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoadForm {
    /// No load dependence.
    Constant,
    /// F = F0 + μ N: needs data at two loads or more.
    Linear,
    /// F = μ N: Amontons; identifiable from one load.
    Proportional,
}

impl LoadForm {
    /// The form a fit should give the classic models: linear when the
    /// training data span loads; proportional when they hold one load but
    /// the model must predict at others (validation data at another load);
    /// constant otherwise.
    pub fn for_data(training_loads_vary: bool, predicts_other_loads: bool) -> Self {
        if training_loads_vary {
            LoadForm::Linear
        } else if predicts_other_loads {
            LoadForm::Proportional
        } else {
            LoadForm::Constant
        }
    }
}

/// A classic model with its fitted parameters.
pub struct Baseline {
    pub kind: BaselineKind,
    pub load_form: LoadForm,
    params: Vec<Parameter>,
}

/// Levels of one evaluation.
struct Levels {
    fc: f64,
    fs: f64,
    vs: f64,
    b: f64,
    sigma0: f64,
    sigma1: f64,
}

impl Baseline {
    /// Bounds and starts from the data's scales (`mean_abs_n`: mean |F|).
    pub fn new(
        kind: BaselineKind,
        load_form: LoadForm,
        scale: &DataScale,
        mean_abs_n: f64,
    ) -> Self {
        let f = scale.friction_n.max(1e-12);
        let v = scale.velocity_m_s.max(1e-9);
        let fc0 = mean_abs_n.clamp(1e-3 * f, f);
        let mut params = Vec::new();
        let level = |params: &mut Vec<Parameter>, name: &str, start: f64, top: f64| {
            let mu_hi = 2.0 * top / scale.load_min_n.max(1e-9);
            let mu = |share: f64| (share * start / scale.load_min_n.max(1e-9)).min(0.5 * mu_hi);
            match load_form {
                LoadForm::Linear => {
                    params.push(Parameter::new(
                        &format!("{name}0_n"),
                        0.0,
                        -2.0 * top,
                        2.0 * top,
                    ));
                    params.push(Parameter::new(
                        &format!("mu_{}", &name[1..]),
                        mu(0.5),
                        0.0,
                        mu_hi,
                    ));
                }
                LoadForm::Proportional => {
                    params.push(Parameter::new(
                        &format!("mu_{}", &name[1..]),
                        mu(1.0),
                        0.0,
                        mu_hi,
                    ));
                }
                LoadForm::Constant => {
                    params.push(Parameter::new(&format!("{name}_n"), start, 0.0, top));
                }
            }
        };
        level(&mut params, "fc", fc0, 2.0 * f);
        if kind != BaselineKind::CoulombViscous {
            level(&mut params, "fs", (1.5 * fc0).min(f), 4.0 * f);
            params.push(Parameter::new("vs_m_s", 0.01 * v, 1e-4 * v, v));
        }
        params.push(Parameter::new("b_n_s_m", 0.0, 0.0, 2.0 * f / v));
        if kind == BaselineKind::LuGre {
            params.push(Parameter::new("sigma0_n_m", 1e5 * f, 1e2 * f, 1e8 * f));
            params.push(Parameter::new("sigma1_n_s_m", 0.0, 0.0, 10.0 * f / v));
        }
        Self {
            kind,
            load_form,
            params,
        }
    }

    fn levels(&self, x: &[f64], load: f64) -> Levels {
        let mut i = 0;
        let mut next = || {
            i += 1;
            x[i - 1]
        };
        let level = |next: &mut dyn FnMut() -> f64| match self.load_form {
            LoadForm::Linear => {
                let a = next();
                a + next() * load
            }
            LoadForm::Proportional => next() * load,
            LoadForm::Constant => next(),
        };
        let fc = level(&mut next);
        let (fs, vs) = if self.kind == BaselineKind::CoulombViscous {
            (fc, 1.0)
        } else {
            let fs = level(&mut next);
            (fs, next())
        };
        let b = next();
        let (sigma0, sigma1) = if self.kind == BaselineKind::LuGre {
            (next(), next())
        } else {
            (0.0, 0.0)
        };
        Levels {
            fc,
            fs,
            vs,
            b,
            sigma0,
            sigma1,
        }
    }
}

fn g(l: &Levels, v: f64) -> f64 {
    l.fc + (l.fs - l.fc) * (-(v / l.vs).powi(2)).exp()
}

fn sgn(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

impl Model for Baseline {
    fn label(&self) -> String {
        match self.load_form {
            LoadForm::Linear => format!("{} (load-linear)", self.kind.label()),
            LoadForm::Proportional => format!("{} (∝ load)", self.kind.label()),
            LoadForm::Constant => self.kind.label().into(),
        }
    }

    fn parameters(&self) -> &[Parameter] {
        &self.params
    }

    fn predict(&self, x: &[f64], s: &Series) -> Result<Vec<f64>, String> {
        let n = s.len();
        let load = |k: usize| s.load_at(k, 1.0);
        if self.kind != BaselineKind::LuGre || s.steady {
            return Ok((0..n)
                .map(|k| {
                    let l = self.levels(x, load(k));
                    let v = s.velocity[k];
                    g(&l, v) * sgn(v) + l.b * v
                })
                .collect());
        }
        let mut out = Vec::with_capacity(n);
        let l0 = self.levels(x, load(0));
        let mut z = g(&l0, s.velocity[0]) * sgn(s.velocity[0]) / l0.sigma0;
        for k in 0..n {
            let l = self.levels(x, load(k));
            let v = s.velocity[k];
            let gv = g(&l, v);
            if gv <= 0.0 {
                return Err(format!("g(v) = {gv} N ≤ 0 at sample {}", k + 1));
            }
            let a = l.sigma0 * v.abs() / gv;
            let dt = if k == 0 { 0.0 } else { s.t[k] - s.t[k - 1] };
            if k > 0 {
                z = if a * dt > 1e-12 {
                    let zs = v / a;
                    zs + (z - zs) * (-a * dt).exp()
                } else {
                    z + v * dt
                };
            }
            let zdot = v - a * z;
            out.push(l.sigma0 * z + l.sigma1 * zdot + l.b * v);
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn scale() -> DataScale {
        DataScale {
            friction_n: 10.0,
            velocity_m_s: 0.1,
            load_min_n: 100.0,
        }
    }

    fn series(steady: bool) -> Series {
        let t: Vec<f64> = (0..2000).map(|k| k as f64 * 1e-3).collect();
        let v: Vec<f64> = t.iter().map(|t| 0.1 * (3.0 * t).sin()).collect();
        let n = t.len();
        Series {
            name: "s".into(),
            steady,
            t,
            velocity: v,
            friction: vec![0.0; n],
            load: None,
            temperature: None,
            fit: vec![true; n],
        }
    }

    #[test]
    fn stribeck_friction_falls_from_the_static_level_to_coulomb_plus_viscous() {
        let m = Baseline::new(BaselineKind::Stribeck, LoadForm::Constant, &scale(), 5.0);
        let x = [4.0, 6.0, 0.01, 20.0];
        let mut s = series(true);
        s.velocity = vec![1e-6, 0.01, 0.1, -0.1];
        s.t.truncate(4);
        let f = m.predict(&x, &s).unwrap();
        assert_relative_eq!(f[0], 6.0 + 20.0 * 1e-6, max_relative = 1e-7);
        assert_relative_eq!(
            f[1],
            4.0 + 2.0 * (-1.0f64).exp() + 0.2,
            max_relative = 1e-12
        );
        assert_relative_eq!(f[2], 4.0 + 2.0);
        assert_relative_eq!(f[3], -6.0);
    }

    #[test]
    fn lugre_in_steady_sliding_is_stribeck_and_lags_after_a_reversal() {
        let lugre = Baseline::new(BaselineKind::LuGre, LoadForm::Constant, &scale(), 5.0);
        let stribeck = Baseline::new(BaselineKind::Stribeck, LoadForm::Constant, &scale(), 5.0);
        let x = [4.0, 6.0, 0.01, 20.0, 1e5, 0.0];
        let s = series(false);
        let fl = lugre.predict(&x, &s).unwrap();
        let fs = stribeck.predict(&x[..4], &s).unwrap();
        // Mid-stroke (v near its peak) the bristles are in steady state.
        let k = 500; // t = 0.5 s, v = 0.1 sin(1.5) ≈ 0.0997
        assert_relative_eq!(fl[k], fs[k], max_relative = 1e-6);
        // Right after the reversal at t = π/3 s the bristles still carry the
        // old direction's deflection: LuGre passes through zero smoothly.
        let rev = (std::f64::consts::PI / 3.0 / 1e-3) as usize;
        assert!(
            fl[rev + 1].abs() < fs[rev + 1].abs(),
            "{} {}",
            fl[rev + 1],
            fs[rev + 1]
        );
        assert_eq!(lugre.parameters().len(), 6);
        assert_eq!(
            Baseline::new(BaselineKind::LuGre, LoadForm::Linear, &scale(), 5.0)
                .parameters()
                .len(),
            8
        );
        assert_eq!(
            Baseline::new(BaselineKind::LuGre, LoadForm::Proportional, &scale(), 5.0)
                .parameters()
                .len(),
            6
        );
    }
}
