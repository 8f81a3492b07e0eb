//! Data → our model: read the sources (the held-out part cut off first),
//! the data's scales, the fitted keys and map coefficients, the contact's
//! scale (chosen from the data for a joint, and under `--fit auto` when the
//! data give no load), everything checked before any simulation. What it makes
//! is [`Prepared`] (`prepared.rs`).

use super::contact_scale::ContactScale;
use super::inputs::DataRequest;
use super::prepared::{split_specs, Prepared};
use super::table_columns;
use super::unknowns::DataScale;
use super::{Data, FitError, ParamSpec, PhysicsModel, Source};
use crate::config::Config;
use std::path::PathBuf;

/// Scales of the training data at the maps' start values: the scale, the
/// mean |F| and whether the load varies.
pub fn data_scale(
    sources: &[Source],
    map: &[f64],
    load_n: f64,
) -> Result<(DataScale, f64, bool), FitError> {
    let (mut f, mut v, mut lmin, mut lmax) = (0.0f64, 0.0f64, f64::INFINITY, 0.0f64);
    let (mut sum_abs, mut n) = (0.0, 0usize);
    let mut all = Vec::with_capacity(sources.len());
    for s in sources {
        let se = s.series(map)?;
        for k in 0..se.len() {
            f = f.max(se.friction[k].abs());
            v = v.max(se.velocity[k].abs());
            let l = se.load_at(k, load_n);
            lmin = lmin.min(l);
            lmax = lmax.max(l);
            sum_abs += se.friction[k].abs();
            n += 1;
        }
        all.push(se);
    }
    if v == 0.0 {
        return Err(FitError::Data {
            what: "data".into(),
            message: "the velocity is zero in every sample: there is no sliding to fit".into(),
        });
    }
    super::sign_convention::check_sign(&all, v)?;
    let scale = DataScale {
        friction_n: f,
        velocity_m_s: v,
        load_min_n: lmin,
        reversal_stiffness_n_m: super::reversals::stiffness(&all).stiffness_n_m,
    };
    Ok((scale, sum_abs / n.max(1) as f64, lmax > 1.01 * lmin))
}

/// The configuration our model runs on, the contact's scale (see
/// `contact_scale.rs`), and the data's scales as the model sees them
/// (through the gain).
#[allow(clippy::too_many_arguments)]
fn model_setup(
    config: &Config,
    units: super::Units,
    choose_scale: bool,
    train: &[Source],
    map_values: &[f64],
    key_specs: &[ParamSpec],
    scale: DataScale,
    notes: &mut Vec<String>,
) -> Result<(Config, Option<ContactScale>, DataScale), FitError> {
    let (c, chosen) =
        super::contact_scale::setup(config, train, map_values, key_specs, units, choose_scale)?;
    let Some(l) = chosen else {
        return Ok((c, None, scale));
    };
    notes.push(format!(
        "the contact's scale: gain {}{}, contact load {} N ({})",
        crate::text::Num::sig(l.gain, 5),
        if units == super::Units::Rotary {
            " m"
        } else {
            ""
        },
        crate::text::Num::sig(l.load_n, 5),
        l.how
    ));
    let load_min = load_range(train, map_values, c.contact.load_n)?.0;
    let contact_scale = scale.through_gain(l.gain, load_min);
    Ok((c, Some(l), contact_scale))
}

/// Where the viscous rise may bend (its exponent fitted, or `--fit auto`,
/// which may choose the bend) and the configuration leaves its reference
/// speed v_b at the default, v_b is the training data's top contact
/// speed: b is then F_v there over that speed, and b and δ are told apart
/// (at v_b = 1 m/s, far above a joint's contact speeds, ln|v/v_b| is
/// nearly the same at every sample and δ moves the rise as b does).
fn read_viscous_rise_at_top_speed(
    model: &mut Config,
    given: &Config,
    auto: bool,
    key_specs: &[ParamSpec],
    scale: &DataScale,
) {
    let bent = auto
        || key_specs
            .iter()
            .any(|s| s.name == "drivetrain.viscous_exponent");
    let default = Config::default().drivetrain.viscous_reference_speed_m_s;
    let top = scale.velocity_m_s;
    if bent
        && given.drivetrain.viscous_reference_speed_m_s == default
        && top.is_finite()
        && top > 0.0
    {
        model.drivetrain.viscous_reference_speed_m_s = top.min(100.0);
    }
}

fn load_range(sources: &[Source], map: &[f64], load_n: f64) -> Result<(f64, f64), FitError> {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for s in sources {
        let se = s.series(map)?;
        for k in 0..se.len() {
            let l = se.load_at(k, load_n);
            lo = lo.min(l);
            hi = hi.max(l);
        }
    }
    Ok((lo, hi))
}

/// A joint turning faster than this, rad/s, is unusual enough to ask
/// whether its velocity is in deg/s.
const FAST_JOINT_RAD_S: f64 = 20.0;

/// Training, held-out and validation sources.
type Sources = (Vec<Source>, Vec<Source>, Vec<Source>);

/// The training, held-out and validation sources of `req`, each file read
/// (its notes into `notes`). `--holdout` cuts each training file in two
/// here, before anything reads it: from then on every choice sees the
/// training part alone.
fn read_sources(req: &DataRequest, notes: &mut Vec<String>) -> Result<Sources, FitError> {
    // Each file with the mapping it is read through (a joint's column
    // names under --rotary), which its held-out cut keeps.
    let mut source = |p: &PathBuf| -> Result<(Source, super::Mapping), FitError> {
        let (table, note) = req.table(p)?;
        notes.extend(note);
        let mapping = if req.rotary {
            table_columns::rotary_columns(&req.mapping, &table, notes)?
        } else {
            table_columns::refuse_joint_columns(&req.mapping, &table)?;
            table_columns::linear_columns(&req.mapping, &table, notes)
        };
        let mut mapping = table_columns::time_column(mapping, &table, notes)?;
        if let Some(c) = &req.friction_offset {
            mapping.friction = format!("({}) - {c}", mapping.friction);
        }
        notes.extend(table_columns::unread_columns(&mapping, &table));
        Ok((Source::new(table, &mapping)?, mapping))
    };
    let given = req
        .files
        .iter()
        .map(&mut source)
        .collect::<Result<Vec<_>, _>>()?;
    let validate = req
        .validate
        .iter()
        .map(|p| source(p).map(|(s, _)| s))
        .collect::<Result<Vec<_>, _>>()?;
    if req.holdout > 0.0 {
        let parts = given
            .iter()
            .map(|(s, mapping)| s.split_held_out(req.holdout, mapping))
            .collect::<Result<Vec<_>, _>>()?;
        let (train, held_out) = parts.into_iter().unzip();
        Ok((train, held_out, validate))
    } else {
        Ok((
            given.into_iter().map(|(s, _)| s).collect(),
            Vec::new(),
            validate,
        ))
    }
}

/// What the data cannot tell or may have wrong, said before the fit: a
/// pre-sliding key without a reversal to identify it, a joint too fast
/// for rad/s.
fn data_warnings(req: &DataRequest, scale: &DataScale, key_specs: &[ParamSpec]) -> Vec<String> {
    let mut notes = Vec::new();
    if scale.reversal_stiffness_n_m.is_none() {
        for s in key_specs.iter().filter(|s| s.name.contains("presliding_")) {
            notes.push(format!(
                "warning: {} is fitted, but the training data hold no usable velocity reversal: pre-sliding shows only through a reversal, so these data cannot identify it (its estimate will follow its start and bounds)",
                s.name
            ));
        }
    }
    if req.rotary && scale.velocity_m_s > FAST_JOINT_RAD_S {
        notes.push(format!(
            "warning: --rotary: the top speed is {} rad/s ({} deg/s); a robot joint rarely turns faster than {FAST_JOINT_RAD_S} rad/s. If the velocity is in deg/s, convert it: --velocity 'NAME * 3.14159265 / 180' (a motor shaft's speed in rad/s is fine as it is)",
            crate::text::Num::sig(scale.velocity_m_s, 5),
            crate::text::Num(scale.velocity_m_s.to_degrees().round())
        ));
    }
    notes
}

/// Temperatures, °C, where a machine's kelvin readings lie (−43 to
/// 127 °C) and few lubricants work: training data all inside are warned
/// of.
const KELVIN_LOOKALIKE_C: (f64, f64) = (230.0, 400.0);

/// A warning when every training temperature reads as kelvin in °C
/// (a room at 293, not 20): a viscosity law then sees a lubricant above
/// 230 °C.
fn kelvin_warning(train: &[Source], map_values: &[f64]) -> Result<Option<String>, FitError> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for s in train {
        let Some(t) = s.series(map_values)?.temperature else {
            return Ok(None);
        };
        for x in t {
            lo = lo.min(x);
            hi = hi.max(x);
        }
    }
    let (a, b) = KELVIN_LOOKALIKE_C;
    Ok((lo.is_finite() && a <= lo && hi <= b).then(|| {
        format!(
            "warning: the temperature lies between {} and {} °C in every training sample, where kelvin readings lie and few lubricants work: if it is in kelvin, convert it: --temperature 'NAME - 273.15'",
            crate::text::Num::sig(lo, 5),
            crate::text::Num::sig(hi, 5)
        )
    }))
}

/// Read the data and set up the parameters (everything checked before any
/// simulation).
pub fn prepare(
    config: &Config,
    req: &DataRequest,
    params: &[ParamSpec],
    auto: bool,
) -> Result<Prepared, FitError> {
    req.check()?;
    let mut notes = Vec::new();
    let (train, held_out, validate) = read_sources(req, &mut notes)?;
    let mapping = &req.mapping;
    let map_names: Vec<String> = mapping.coefficients.iter().map(|c| c.0.clone()).collect();
    let map_values: Vec<f64> = mapping.coefficients.iter().map(|c| c.1).collect();
    let load_n = config.contact.load_n;
    let (scale, mean_abs_n, loads_vary) = data_scale(&train, &map_values, load_n)?;
    for v in &validate {
        super::sign_convention::check_validation(&v.series(&map_values)?)?;
    }
    let load_given = train
        .iter()
        .map(|s| s.series(&map_values).map(|se| se.load.is_some()))
        .collect::<Result<Vec<_>, _>>()?
        .into_iter()
        .any(|g| g);
    let (key_specs, map_fit) = split_specs(params, &map_names, &map_values)?;
    notes.extend(data_warnings(req, &scale, &key_specs));
    notes.extend(kelvin_warning(&train, &map_values)?);
    // The scale is chosen for a joint's data, and under --fit auto for
    // data that do not give the load when the configuration does not
    // either: a `contact.load_n` other than the default is the user's
    // statement of the contact's scale, and is kept.
    let load_configured = config.contact.load_n != Config::default().contact.load_n;
    let choose_scale = req.rotary || (auto && !load_given && !load_configured);
    let (mut model_config, contact_scale, model_scale) = model_setup(
        config,
        req.units(),
        choose_scale,
        &train,
        &map_values,
        &key_specs,
        scale,
        &mut notes,
    )?;
    read_viscous_rise_at_top_speed(&mut model_config, config, auto, &key_specs, &model_scale);
    let gain = contact_scale.as_ref().map_or(1.0, |l| l.gain);
    let model = PhysicsModel::new(&model_config, &key_specs, &model_scale)?.with_gain(gain);
    Ok(Prepared {
        model_config,
        model_scale,
        contact_scale,
        joint: req.topics.joint.clone().unwrap_or_else(|| "joint".into()),
        names: req.files.iter().map(|p| p.display().to_string()).collect(),
        data: Data {
            train,
            held_out,
            validate,
            holdout: super::data::HoldOut::None,
            map_names,
            map_values,
            units: req.units(),
        },
        model,
        map_fit,
        scale,
        mean_abs_n,
        loads_vary,
        load_given,
        notes,
    })
}
