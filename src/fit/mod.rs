//! Calibration: fit the model's unknowns (any numeric configuration key,
//! and the coefficients of the input maps) to recorded friction, and fit
//! the classic models (Coulomb + viscous, Stribeck, LuGre) to the same data
//! with the same optimiser, so that the comparison is honest.
//!
//! The method is bounded nonlinear least squares on the friction residual
//! r_k = F_model(t_k; p) − F_measured(t_k):
//!
//! | step | how |
//! |---|---|
//! | scaling | each parameter on its log scale (positive bounds) or linear scale, mapped to an unbounded variable by the sine transform s = lo + (hi − lo)(1 + sin u)/2 |
//! | global phase | a seeded Latin-hypercube set of starts over the scaled bounds, each scored by one simulation |
//! | linear parameters | solved, not searched: the parameters the residuals are linear in with fixed slopes (the drivetrain's viscous and quadratic losses, map coefficients that scale or offset the measured friction) are set at every point the local runs evaluate to their best values in their bounds (variable projection; `--linear-keys searched` searches them as the others) |
//! | cheap parameters | the keys whose change only recomposes the friction along the kept film, fitted at every point of the film's keys with the film held, the local runs searching the film's keys alone (`profile.rs`; `--cheap-keys searched` searches them with the film's keys) |
//! | local phase | Levenberg–Marquardt (MINPACK, `levenberg-marquardt` on nalgebra) from the given start, then the best distinct global starts side by side, each stopped inside the first optimum's 95 % confidence region or, with `--later-runs valley` (opt-in), as soon as a straight line from it falls all the way to that optimum (the valley test); Jacobian by forward differences of whole simulations run in parallel, kept up to date between them by Broyden's secant update and polished on differences at the end |
//! | statistics | standard errors s²(JᵀJ)⁻¹ and correlations from the Jacobian in scaled coordinates at the optimum; flags at bounds and for |corr| > 0.95 |
//!
//! Transient data are simulated from the steady state of the first sample
//! (as `simulate` does), on the solver's fixed step, with the inputs
//! interpolated linearly between samples and the friction read at the sample
//! times; steady curves are solved point by point with the steady solver.
//!
//! Files top-down: the flow first, in its order, then what it stands on;
//! a file uses only files below it (`tests/module_maps.rs` checks it).
//!
//! | file | content |
//! |---|---|
//! | `request.rs` | a calibration as data ([`request::FitRequest`]) and its one flow, `run`, for the command line and Python: prepare → select → fit ours → the fitted file → the classic models → the report |
//! | `offset_try.rs` | `--fit auto`'s rule 12: where the direction asymmetry was chosen on a time series, the calibration again with an offset fitted as an input map, kept where it pays |
//! | `prepare.rs` | data → our model: the sources (the held-out part cut off first), scales, keys, maps, the contact's scale |
//! | `table_columns.rs` | a table's columns as a fit's inputs: a joint's columns under `--rotary` (deg/s, rpm converted), a time column named with its unit, what was meant when a default column is missing, the columns not read |
//! | `confirm.rs` | `--fit auto`'s choice confirmed at the final fit's optimum: scored on the same folds, it falls back to the best set with one term fewer when it no longer pays over it, or to the lighter set of two chosen terms that are confounded at that optimum |
//! | `selection_report.rs` | `--fit auto`'s report: the rule in words, every set tried with its error per fold, what was left out, not admitted, added and removed, the choice and why it stopped |
//! | `select.rs` | `--fit auto`'s rule: stepwise with removal on cross-validation, terms that pay, dead terms dropped; its report |
//! | `moves.rs` | the moves a step of `--fit auto` tries: each open candidate, and a term with the term it needs |
//! | `stop_reason.rs` | why the stepwise selection stopped, in words: the best next term does not pay on the folds, or the whole curve's criterion refuses it |
//! | `classic_shape.rs` | `--fit auto`'s rule 7: a steady curve starts from the classic shape its points support (AICc), which is presumed |
//! | `curve_support.rs` | `--fit auto`'s rule 10: on a steady curve a term enters only where the whole curve's AICc is lowered too |
//! | `removal.rs` | terms taken away during the selection: one that no longer pays, one flagged dead, one of two confounded terms; whether a change pays |
//! | `lighter_sets.rs` | the sets a removal may go to: a term's lighter forms, the term taken away, a displaced fuller form taken back; the change's words |
//! | `trial.rs` | one set of terms tried: fitted on the training data, scored by cross-validation |
//! | `trial_starts.rs` | a trial's starts besides its warm one: new keys at their placements, the Stribeck curve at its classic curves, a set reached by taking a term away also where it would be fitted alone |
//! | `admission.rs` | `--fit auto`'s rule 9: a term that grows without end past the data (the quadratic) admitted only where its fit tells its coefficient from zero |
//! | `candidates.rs` | the candidate terms, the keys of a set, which candidates the data allow, the keys `--fit auto` starts from |
//! | `compare.rs` | ours and the classic models fitted on the same data with the same optimiser |
//! | `report.rs` | the summary, the parameter tables, the report folder, the fitted YAML |
//! | `models_table.rs` | the models table: ours and each classic on the same yardstick; the verdict |
//! | `report_plots.rs` | a report's plots: fit and residuals per series, every model's residual against velocity |
//! | `by_direction.rs` | the residual by direction of motion: level and offset errors |
//! | `calibrated_range.rs` | the calibrated range from the training samples (into the fitted file); where held-out data lie against it, the error inside and outside |
//! | `inertia_check.rs` | whether a fit's residual follows the acceleration (a drive force that still holds m·a): the mass it points to, a warning |
//! | `cross_validate.rs` | cross-validation by what a calibration is used for: the folds (files, time blocks, speed ranges) and each fold's refit |
//! | `prepared.rs` | what `prepare` makes: the data and our model for them; our model for another set of keys |
//! | `driver.rs` | one model's whole fit: global phase, local runs, statistics, predictions |
//! | `multistart.rs` | the global phase, then local runs from the best distinct starts; the distinct optima |
//! | `bound_polish.rs` | a local run that spent its budget beside a bound: those parameters held on it and the others fitted, kept where the bound is active |
//! | `local_run.rs` | one Levenberg–Marquardt run: secant or difference Jacobians, the partial refresh, the polish, what was still moving |
//! | `earlier_optima.rs` | the optima earlier runs found: a later run's stop inside one's confidence region or, opt-in, in its valley |
//! | `separable.rs` | the parameters the residuals are linear in, solved exactly in their bounds at every point; the local runs' variables (the others) |
//! | `profile.rs` | the cheap keys (a change recomposes the friction along the kept film) fitted at every point of the film's keys, in their bounds |
//! | `box_qp.rs` | a convex quadratic's exact minimum over a box: the linear keys' solve, the cheap keys' steps |
//! | `stats.rs` | standard errors, correlations, flags |
//! | `options.rs` | how a fit searches: the user's settings, each fit's options, the Jacobian and later-run rules |
//! | `physics_model.rs` | our model as a predictor: its keys, its film reused when only the terms after it change, its linear keys |
//! | `film_run.rs` | our model's film along a series (transient and steady solves), the trace it keeps, the friction recomposed along it |
//! | `kept_columns.rs` | factors of the speed alone (the boundary rate's asinh, the Stribeck fall, the viscous bend) kept along a film trace for the last key values composed with |
//! | `baselines.rs` | Coulomb + viscous, Stribeck, LuGre |
//! | `classic_regression.rs` | the classic curves by linear least squares on the training samples (Stribeck on a grid of speeds): the classics' starts and our Stribeck term's |
//! | `problem.rs` | the problem: a model, the data and its map coefficients, residuals, predictions |
//! | `data.rs` | the data of a fit: training, held-out and validation sources by role, with the maps' coefficients |
//! | `contact_scale.rs` | the contact's gain and load chosen from the data (a joint's lever, a linear axis's gain); a key's value as it acts on the joint |
//! | `unknowns.rs` | the fitted parameters: bounds, scales, configuration keys; the data's scales |
//! | `reversals.rs` | velocity reversals in the data and the stiffness through them (pre-sliding starts) |
//! | `sign_convention.rs` | friction's sign against the velocity's: a logged reaction or a magnitude refused, with the fix |
//! | `inputs.rs` | what is read: the data files, held out and validation files, their mapping, a bag's topics; one file into a table |
//! | `bag_input.rs` | topics of a bag → a table |
//! | `held_out.rs` | `--holdout`: the rows held out, the table cut in two before anything reads it, a later part scored after the motion before it |
//! | `series.rs` | a table and its mapping → the model's inputs |
//! | `expr.rs` | column expressions: compiling, affine fast path, `ddt` and `smooth` replaced by their columns |
//! | `windowed.rs` | columns made over ±`--smooth` windows: `ddt`'s local linear slope, `smooth`'s kernel that slope implies |
//! | `synthetic.rs` | synthetic data: the model along a motion, with noise |
//! | `error.rs` | [`FitError`] (setup) and [`PredictError`] (no prediction at some parameter values) |
//! | `units.rs` | the data's units: m/s and N, or rad/s and N·m |

pub mod admission;
#[cfg(feature = "mcap")]
pub mod bag_input;
pub mod baselines;
pub mod bound_polish;
mod box_qp;
pub mod by_direction;
pub mod calibrated_range;
pub mod candidates;
pub mod classic_regression;
pub mod classic_shape;
pub mod compare;
pub mod confirm;
pub mod contact_scale;
pub mod cross_validate;
mod curve_support;
pub mod data;
pub mod driver;
pub mod earlier_optima;
pub mod error;
mod expr;
mod film_run;
mod held_out;
pub mod inertia_check;
pub mod inputs;
mod kept_columns;
mod lighter_sets;
pub mod local_run;
pub mod models_table;
mod moves;
pub mod multistart;
pub mod offset_try;
pub mod options;
pub mod physics_model;
pub mod prepare;
pub mod prepared;
pub mod problem;
mod profile;
mod removal;
pub mod report;
#[cfg(feature = "plots")]
pub mod report_plots;
pub mod request;
pub mod reversals;
pub mod select;
pub mod selection_report;
pub mod separable;
pub mod series;
pub mod sign_convention;
pub mod stats;
pub mod stop_reason;
pub mod synthetic;
pub mod table_columns;
pub mod trial;
mod trial_starts;
pub mod units;
pub mod unknowns;
mod windowed;

pub use crate::table::{Delimiter, Table, TableError};
pub use baselines::{Baseline, BaselineKind};
pub use classic_regression::LoadForm;
pub use data::Data;
pub use driver::FitOutcome;
pub use error::{FitError, PredictError};
pub use options::Options;
pub use physics_model::PhysicsModel;
pub use problem::Model;
pub use series::{Mapping, Series, Source};
pub use units::Units;
pub use unknowns::{FittedParameter, ParamSpec};
