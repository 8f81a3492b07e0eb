//! The physics core: the transient mixed-lubrication model of Driesen et al.
//! 2023 as specified in `MODEL.md`, advanced in fixed steps.
//!
//! This module has no middleware, file, clock or logging dependency; it builds
//! and tests with `--no-default-features`. Everything is SI (m, s, N, Pa,
//! Pa·s, kg). Each submodule documents its symbols and equations:
//!
//! | module | content |
//! |---|---|
//! | [`params`] | parameters and their defaults (paper Tables A2–A4) |
//! | [`geometry`] | film shape h = h0 + hg + ht, finite-volume grid |
//! | [`eos`] | mixture cavitation equation of state |
//! | [`gw`] | Greenwood–Williamson contact, exact F_n tables |
//! | [`flow_factors`] | Patir–Cheng flow factors (optional) |
//! | [`scheme`] | three-level θ / BDF2 time discretisation |
//! | [`solver`] | discretised Reynolds + load balance, Newton, steady mode, the paper's Algorithm 1 |
//! | [`estimate`] | per-step output, status and diagnostics |
//! | [`error`] | the core's setup errors ([`SetupError`]) |
//! | [`drivetrain`] | losses beside the contact (bearings, seals, gears) |
//! | [`presliding`] | the contact's elastic displacement before gross sliding |
//! | [`boundary`] | the boundary film's friction rising with the logarithm of speed (Eyring) |
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

pub mod boundary;
pub mod drivetrain;
pub mod eos;
pub mod error;
pub mod estimate;
pub mod flow_factors;
pub mod geometry;
pub mod gw;
pub mod params;
pub mod presliding;
pub mod scheme;
pub mod solver;
pub mod viscosity;

pub use boundary::BoundaryRate;
pub use drivetrain::Drivetrain;
pub use error::SetupError;
pub use estimate::{Diagnostics, Estimate, Regime, Status};
pub use params::{
    Contact, CouetteFlux, Geometry, Limiter, Lubricant, Method, ModelParams, Pocket, Profile,
    ReferenceSettings, Roughness, SolverSettings, TimeScheme, WidthLaw,
};
pub use presliding::Presliding;
pub use solver::{FieldPoint, Isa, ModelMismatch, PreparedModel, Solver, StepBreakdown};
pub use viscosity::{ViscosityModel, VogelModel};
