//! Method of manufactured solutions for the transient Reynolds equation with
//! the mixture equation of state (docs/model.md §10).
//!
//! A pressure p(x,t), gap h0(t) and velocity v(t) are chosen; the residual of
//! ∂t(ρh) + ∂x q = S is added as a mass source, and the discrete solution is
//! compared with the chosen p. The cell integral of ∂x q is exactly
//! q(x_right) − q(x_left); the storage part is integrated by 5-point Gauss.

use friction_node::physics::eos::MixtureEos;
use friction_node::physics::*;
use std::f64::consts::PI;

struct Case {
    model: ModelParams,
    eos: MixtureEos,
    /// p(x,t) and its x-derivatives and t-derivative.
    p: Box<dyn Fn(f64, f64) -> [f64; 4]>,
    h0: Box<dyn Fn(f64) -> [f64; 2]>,
    v: Box<dyn Fn(f64) -> f64>,
}

impl Case {
    fn len(&self) -> f64 {
        self.model.geometry.length
    }

    /// h(x,t), ∂x h, ∂t h for the parabolic profile.
    fn h(&self, x: f64, t: f64) -> [f64; 3] {
        let Profile::Parabolic { depth } = self.model.geometry.profile else {
            unreachable!()
        };
        let l = self.len();
        let xi = x / l - 0.5;
        let [h0, dh0] = (self.h0)(t);
        [h0 + 4.0 * depth * xi * xi, 8.0 * depth * xi / l, dh0]
    }

    /// Exact mass flux q(x,t).
    fn q(&self, x: f64, t: f64) -> f64 {
        let [p, px, _, _] = (self.p)(x, t);
        let [h, _, _] = self.h(x, t);
        let s = self.eos.eval(p);
        -(s.rho / s.mu) * h * h * h * px / 12.0 + 0.5 * (self.v)(t) * s.rho * h
    }

    /// ∂t(ρh)(x,t).
    fn storage_rate(&self, x: f64, t: f64) -> f64 {
        let [p, _, _, pt] = (self.p)(x, t);
        let [h, _, ht] = self.h(x, t);
        let s = self.eos.eval(p);
        s.drho * pt * h + s.rho * ht
    }

    /// Cell-integrated source for N cells at time t.
    fn source(&self, n: usize, t: f64, transient: bool) -> Vec<f64> {
        const GX: [f64; 5] = [
            -0.906_179_845_938_664,
            -0.538_469_310_105_683,
            0.0,
            0.538_469_310_105_683,
            0.906_179_845_938_664,
        ];
        const GW: [f64; 5] = [
            0.236_926_885_056_189,
            0.478_628_670_499_366,
            0.568_888_888_888_889,
            0.478_628_670_499_366,
            0.236_926_885_056_189,
        ];
        let dx = self.len() / n as f64;
        (0..n)
            .map(|i| {
                let (a, b) = (i as f64 * dx, (i + 1) as f64 * dx);
                let mut s = self.q(b, t) - self.q(a, t);
                if transient {
                    let mid = 0.5 * (a + b);
                    s += 0.5
                        * dx
                        * GX.iter()
                            .zip(GW)
                            .map(|(g, w)| w * self.storage_rate(mid + 0.5 * dx * g, t))
                            .sum::<f64>();
                }
                s
            })
            .collect()
    }

    fn exact(&self, n: usize, t: f64) -> Vec<f64> {
        let dx = self.len() / n as f64;
        (0..n)
            .map(|i| (self.p)((i as f64 + 0.5) * dx, t)[0])
            .collect()
    }
}

fn max_err(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn order(e: &[f64]) -> Vec<f64> {
    e.windows(2).map(|w| (w[0] / w[1]).log2()).collect()
}

/// p = p_amb + A sin(πx/L)·(1 + 0.5 sin ωt) (A > 0: full film; A < 0: the
/// film dips into the cavitation range of the EOS).
fn case(amplitude: f64, alpha_s: f64) -> Case {
    let mut model = ModelParams::default();
    model.lubricant.vapour_fraction_saturation = alpha_s;
    let eos = MixtureEos::new(&model.lubricant);
    let l = model.geometry.length;
    let w = 2.0 * PI * 5.0;
    let p_amb = model.lubricant.ambient_pressure;
    Case {
        model,
        eos,
        p: Box::new(move |x, t| {
            let (s, c) = ((PI * x / l).sin(), (PI * x / l).cos());
            let f = 1.0 + 0.5 * (w * t).sin();
            let ft = 0.5 * w * (w * t).cos();
            [
                p_amb + amplitude * s * f,
                amplitude * PI / l * c * f,
                -amplitude * (PI / l).powi(2) * s * f,
                amplitude * s * ft,
            ]
        }),
        h0: Box::new(move |t| {
            [
                15e-6 * (1.0 + 0.2 * (w * t).sin()),
                15e-6 * 0.2 * w * (w * t).cos(),
            ]
        }),
        v: Box::new(move |t| (w * t).cos()),
    }
}

fn steady_error(c: &Case, n: usize) -> f64 {
    steady_error_with(c, n, CouetteFlux::Upwind)
}

fn steady_error_with(c: &Case, n: usize, flux: CouetteFlux) -> f64 {
    let st = SolverSettings {
        cells: n,
        tolerance: 1e-12,
        flux,
        ..Default::default()
    };
    let mut s = Solver::new(&c.model, &st).unwrap();
    s.set_mass_source(Some(&c.source(n, 0.0, false)));
    let e = s.steady_prescribed_gap((c.v)(0.0), (c.h0)(0.0)[0], 1.0);
    assert_eq!(e.status, Status::Converged);
    let amp = ((c.p)(0.5 * c.len(), 0.0)[0] - c.model.lubricant.ambient_pressure).abs();
    max_err(s.pressure(), &c.exact(n, 0.0)) / amp
}

#[test]
fn full_film_pressure_converges_at_second_order_in_dx() {
    let c = case(2e6, 1e-9);
    let e: Vec<f64> = [32, 64, 128, 256]
        .iter()
        .map(|&n| steady_error(&c, n))
        .collect();
    let o = order(&e);
    eprintln!("full film: errors {e:?} orders {o:?}");
    assert!(e[3] < 1e-4, "errors {e:?}");
    for k in &o {
        assert!((1.8..2.3).contains(k), "orders {o:?}, errors {e:?}");
    }
}

#[test]
fn cavitating_pressure_converges_at_first_order_in_dx_with_upwinded_density() {
    // p dips to 1e4 Pa, through the liquid–vapour transition (α up to ~0.9):
    // the upwinded density makes the scheme first order there.
    let c = case(-9e4, 0.01);
    let e: Vec<f64> = [32, 64, 128, 256, 512]
        .iter()
        .map(|&n| steady_error(&c, n))
        .collect();
    let o = order(&e);
    eprintln!("cavitating: errors {e:?} orders {o:?}");
    assert!(e[4] < 2e-2, "errors {e:?}");
    for k in &o[1..] {
        assert!((0.8..1.3).contains(k), "orders {o:?}, errors {e:?}");
    }
}

const LIMITERS: [Limiter; 3] = [Limiter::Minmod, Limiter::VanLeer, Limiter::VanAlbada];

#[test]
fn full_film_pressure_converges_at_second_order_in_dx_with_the_muscl_flux() {
    let c = case(2e6, 1e-9);
    for l in LIMITERS {
        let e: Vec<f64> = [32, 64, 128, 256]
            .iter()
            .map(|&n| steady_error_with(&c, n, CouetteFlux::Muscl(l)))
            .collect();
        let o = order(&e);
        eprintln!("full film, MUSCL {l:?}: errors {e:?} orders {o:?}");
        assert!(e[3] < 1e-4, "{l:?}: errors {e:?}");
        for k in &o {
            assert!((1.8..2.3).contains(k), "{l:?}: orders {o:?}, errors {e:?}");
        }
    }
}

#[test]
fn cavitating_pressure_converges_faster_than_first_order_with_the_muscl_flux() {
    // The case of the upwind test above; the limiter falls back to first
    // order only at the few cells where the density has an extremum.
    let c = case(-9e4, 0.01);
    for l in LIMITERS {
        let e: Vec<f64> = [32, 64, 128, 256, 512]
            .iter()
            .map(|&n| steady_error_with(&c, n, CouetteFlux::Muscl(l)))
            .collect();
        let up = steady_error(&c, 512);
        let o = order(&e);
        eprintln!("cavitating, MUSCL {l:?}: errors {e:?} orders {o:?} (upwind at 512: {up:e})");
        // Measured: orders 1.4–1.6 at N = 32 rising to 1.93–2.02 at 512.
        for k in &o[2..] {
            assert!((1.8..2.3).contains(k), "{l:?}: orders {o:?}, errors {e:?}");
        }
        assert!(e[4] < up / 10.0, "{l:?}: {} vs upwind {up}", e[4]);
    }
}

fn transient_error(c: &Case, scheme: TimeScheme, n: usize, steps: usize, t_end: f64) -> Vec<f64> {
    let dt = t_end / steps as f64;
    let st = SolverSettings {
        cells: n,
        dt,
        scheme,
        tolerance: 1e-12,
        ..Default::default()
    };
    let mut s = Solver::new(&c.model, &st).unwrap();
    s.initialize_state(&c.exact(n, 0.0), (c.h0)(0.0)[0])
        .unwrap();
    let weights = match scheme {
        TimeScheme::Bdf2 => [1.0, 0.0, 0.0],
        TimeScheme::Theta { theta1, theta2 } => [
            0.5 * (theta1 + theta2),
            1.0 - theta2,
            0.5 * (theta2 - theta1),
        ],
    };
    for k in 1..=steps {
        let t = k as f64 * dt;
        // The first step is backward Euler; then the scheme's force weights
        // apply to the source like to every other force.
        let w = if k == 1 { [1.0, 0.0, 0.0] } else { weights };
        let mut src = vec![0.0; n];
        for (j, wj) in w.iter().enumerate() {
            if *wj != 0.0 {
                for (a, b) in src.iter_mut().zip(c.source(n, t - j as f64 * dt, true)) {
                    *a += wj * b;
                }
            }
        }
        s.set_mass_source(Some(&src));
        let e = s.step_prescribed_gap((c.v)(t), (c.h0)(t)[0], 1.0);
        assert_eq!(e.status, Status::Converged, "step {k}");
    }
    s.pressure().to_vec()
}

fn time_orders(scheme: TimeScheme) -> (Vec<f64>, Vec<f64>) {
    // Self-convergence in Δt on a fixed grid isolates the temporal error.
    let c = case(2e6, 1e-9);
    let (n, t_end) = (64, 0.1);
    let sols: Vec<Vec<f64>> = [10, 20, 40, 80, 160, 320]
        .iter()
        .map(|&k| transient_error(&c, scheme, n, k, t_end))
        .collect();
    let e: Vec<f64> = sols
        .windows(2)
        .map(|w| max_err(&w[0], &w[1]) / 2e6)
        .collect();
    (order(&e), e)
}

#[test]
fn bdf2_converges_at_second_order_in_dt() {
    let (o, e) = time_orders(TimeScheme::Bdf2);
    eprintln!("BDF2: differences {e:?} orders {o:?}");
    for k in &o[1..] {
        assert!((1.8..2.3).contains(k), "orders {o:?}, errors {e:?}");
    }
    let last = o[o.len() - 1];
    assert!((1.9..2.1).contains(&last), "orders {o:?}");
}

#[test]
fn paper_theta_scheme_converges_at_second_order_in_dt() {
    let (o, e) = time_orders(TimeScheme::PAPER);
    eprintln!("theta (2, 0.8): differences {e:?} orders {o:?}");
    for k in &o[1..] {
        assert!((1.7..2.4).contains(k), "orders {o:?}, errors {e:?}");
    }
    let last = o[o.len() - 1];
    assert!((1.9..2.1).contains(&last), "orders {o:?}");
}

#[test]
fn transient_solution_tracks_the_manufactured_pressure() {
    // Against the exact solution (not only self-convergence).
    let c = case(2e6, 1e-9);
    let p = transient_error(&c, TimeScheme::Bdf2, 128, 200, 0.1);
    let err = max_err(&p, &c.exact(128, 0.1)) / 2e6;
    eprintln!("transient MMS relative error {err:.3e}");
    assert!(err < 2e-3, "relative error {err:e}");
}
