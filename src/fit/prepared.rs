//! A calibration's data and our model as prepared for it: the sources
//! (training, held out, validation), the data's scales, the fitted keys and
//! map coefficients, the contact's scale; and our model for another set
//! of keys on the same data (what `--fit auto` tries).

use super::contact_scale::ContactScale;
use super::unknowns::{map_parameter, DataScale};
use super::{Data, FitError, FittedParameter, ParamSpec, PhysicsModel};
use crate::config::Config;

/// Data, the physics model's parameters and the fitted map coefficients.
pub struct Prepared {
    /// The sources.
    pub data: Data,
    /// Our model with its fitted keys.
    pub model: PhysicsModel,
    /// Fitted map coefficients (index, bounds).
    pub map_fit: Vec<(usize, FittedParameter)>,
    /// The data's velocity and friction scales (for the baselines' starts and bounds).
    pub scale: DataScale,
    /// Mean |friction| of the training data, N.
    pub mean_abs_n: f64,
    /// Whether the training loads differ by more than 1 %.
    pub loads_vary: bool,
    /// Whether the training data give the load (a load column or topic),
    /// rather than the configuration's `contact.load_n`.
    pub load_given: bool,
    /// The training files, as given.
    pub names: Vec<String>,
    /// What was read from each bag (topics used, warnings).
    pub notes: Vec<String>,
    /// The contact's gain and load when the data's axis drives it through
    /// one (chosen from the data, or configured).
    pub contact_scale: Option<ContactScale>,
    /// The joint's name in the fitted file (`--joint`, else `joint`).
    pub joint: String,
    /// The configuration our model runs on (a rotary joint's contact with
    /// its chosen load).
    pub model_config: Config,
    /// The data's scales as our model sees them (through the gain).
    pub model_scale: DataScale,
}

/// Fitted map coefficients: index into the data's maps and bounds.
pub type MapFit = Vec<(usize, FittedParameter)>;

/// Split specs into configuration keys and map coefficients (with their
/// bounds resolved).
pub(super) fn split_specs(
    specs: &[ParamSpec],
    map_names: &[String],
    map_values: &[f64],
) -> Result<(Vec<ParamSpec>, MapFit), FitError> {
    let mut key_specs = Vec::new();
    let mut map_fit = Vec::new();
    for s in specs {
        if s.name.contains('.') {
            key_specs.push(s.clone());
        } else if let Some(i) = map_names.iter().position(|n| *n == s.name) {
            map_fit.push((i, map_parameter(s, map_values[i])?));
        } else {
            return Err(FitError::Key {
                key: s.name.clone(),
                message:
                    "neither a configuration key (dotted, e.g. roughness.sigma_m) nor a --map coefficient"
                        .into(),
            });
        }
    }
    Ok((key_specs, map_fit))
}

/// Our model for `specs` on `p`'s data (the contact's gain included)
/// and its fitted map coefficients, every parameter started at its value
/// in `warm` when it has one (the bounds stay those of `specs`).
pub fn model_for(
    p: &Prepared,
    specs: &[ParamSpec],
    warm: &[(String, f64)],
) -> Result<(PhysicsModel, MapFit), FitError> {
    let (key_specs, mut map_fit) = split_specs(specs, &p.data.map_names, &p.data.map_values)?;
    let gain = p.contact_scale.as_ref().map_or(1.0, |l| l.gain);
    let mut model = PhysicsModel::new(&p.model_config, &key_specs, &p.model_scale)?
        .with_gain(gain)
        .with_traces(p.model.traces());
    model.warm(warm);
    for (_, q) in &mut map_fit {
        if let Some((_, v)) = warm.iter().find(|(n, _)| *n == q.name) {
            q.warm(*v);
        }
    }
    Ok((model, map_fit))
}
