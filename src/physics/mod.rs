//! The physics core: the transient mixed-lubrication model of Driesen et al.
//! 2023 as specified in `docs/model.md`, advanced in fixed steps.
//!
//! This module has no middleware, file, clock or logging dependency; it builds
//! and tests with `--no-default-features`. Everything is SI (m, s, N, Pa,
//! Pa·s, kg). Each submodule documents its symbols and equations:
//!
//! | module | content |
//! |---|---|
//! | [`params`] | physical parameters and their defaults (paper Tables A2–A4) |
//! | [`settings`] | the solver's numerical settings: method, time scheme, grid, tolerances, flux |
//! | [`geometry`] | film shape h = h0 + hg + ht, finite-volume grid |
//! | [`eos`] | mixture cavitation equation of state |
//! | [`gw`] | Greenwood–Williamson contact, exact F_n tables |
//! | [`flow_factors`] | Patir–Cheng flow factors (optional) |
//! | [`scheme`] | three-level θ / BDF2 time discretisation |
//! | [`solver`] | discretised Reynolds + load balance, Newton, steady mode, the paper's Algorithm 1 |
//! | [`estimate`] | per-step output, status and diagnostics |
//! | [`error`] | the core's setup errors ([`SetupError`]) |
//! | [`terms`] | the friction terms beside the film's shear (boundary friction and its rate, pre-sliding, soft width, drivetrain), their keys' catalogue and their composition |
//! | [`viscosity`] | the liquid's viscosity against temperature (Vogel) |
//!
//! ```
//! use friction_node::physics::{ModelParams, SolverSettings, Solver};
//! let mut s = Solver::new(&ModelParams::default(), &SolverSettings { cells: 64, ..Default::default() }).unwrap();
//! s.initialize_steady(0.0, 20_762.0);
//! let e = s.step(0.01, 20_762.0);
//! assert!(e.status.is_converged());
//! assert!(e.cof > 0.2 && e.cof < 0.31);
//! ```

#![warn(clippy::float_cmp)]

pub mod eos;
pub mod error;
pub mod estimate;
pub mod flow_factors;
pub mod geometry;
pub mod gw;
pub mod params;
pub mod scheme;
pub mod settings;
pub mod solver;
pub mod terms;
pub mod viscosity;

pub use error::SetupError;
pub use estimate::{Diagnostics, Estimate, Regime, Status};
pub use params::{Contact, Geometry, Lubricant, ModelParams, Pocket, Profile, Roughness};
pub use settings::{CouetteFlux, Limiter, Method, ReferenceSettings, SolverSettings, TimeScheme};
pub use solver::{FieldPoint, Isa, ModelMismatch, PreparedModel, Solver, StepBreakdown};
pub use terms::boundary_film::BoundaryRate;
pub use terms::drivetrain::Drivetrain;
pub use terms::presliding::Presliding;
pub use terms::soft_width::WidthLaw;
pub use terms::{sgn, FrictionTerm, FrictionTerms, TermStates};
pub use viscosity::{ViscosityModel, VogelModel};
