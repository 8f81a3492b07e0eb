//! Data → our model: read the sources (the held-out part cut off first),
//! the data's scales, the fitted keys and map coefficients, the contact's
//! scale (chosen from the data for a joint, and under `--fit auto` when the
//! data give no load), everything checked before any simulation. What it makes
//! is [`Prepared`] (`prepared.rs`).

use super::contact_scale::ContactScale;
use super::inputs::DataRequest;
use super::prepared::{split_specs, Prepared};
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

/// The column names a joint's table may use for the velocity when
/// `--velocity` keeps its default, each with its factor to rad/s.
const ROTARY_VELOCITY_COLUMNS: &[(&str, f64)] = &[
    ("velocity_rad_s", 1.0),
    ("velocity_deg_s", std::f64::consts::PI / 180.0),
    ("velocity_rpm", std::f64::consts::PI / 30.0),
];
/// The column names a joint's table may use for the friction when
/// `--friction` keeps its default, N·m.
const ROTARY_FRICTION_COLUMNS: &[&str] =
    &["friction_nm", "friction_n_m", "torque_nm", "torque_n_m"];

/// `--rotary` with the default column names: a table without
/// `velocity_m_s` / `friction_n` but with a joint's names (`velocity_rad_s`,
/// `velocity_deg_s`, `velocity_rpm`, `friction_nm`, `torque_nm`, …) is read
/// through those, a velocity in deg/s or rpm converted to rad/s (said in
/// `notes`). A table with none of them is an error that names them.
fn rotary_columns(
    mapping: &super::Mapping,
    table: &super::Table,
    notes: &mut Vec<String>,
) -> Result<super::Mapping, FitError> {
    let defaults = super::Mapping::default();
    // A column by name, numeric or not (a text column is named by the
    // expression that reads it).
    let has = |c: &str| table.index(c).is_some();
    let keeps = |given: &str, default: &str| given != default || has(given);
    let velocity = if keeps(&mapping.velocity, &defaults.velocity) {
        mapping.velocity.clone()
    } else {
        let &(name, to_rad_s) = ROTARY_VELOCITY_COLUMNS
            .iter()
            .find(|(c, _)| has(c))
            .ok_or_else(|| {
                let names: Vec<&str> = ROTARY_VELOCITY_COLUMNS.iter().map(|(c, _)| *c).collect();
                unknown_column(
                    table,
                    "velocity",
                    &names,
                    "in rad/s (a column in deg/s: `--velocity 'COLUMN * 0.017453292519943295'`)",
                )
            })?;
        if to_rad_s == 1.0 {
            name.to_string()
        } else {
            notes.push(format!(
                "{}: the velocity is `{name}`, read as rad/s: `{name} * {to_rad_s:e}`",
                table.source.display()
            ));
            format!("{name} * {to_rad_s:e}")
        }
    };
    let friction = if keeps(&mapping.friction, &defaults.friction) {
        mapping.friction.clone()
    } else {
        ROTARY_FRICTION_COLUMNS
            .iter()
            .find(|c| has(c))
            .ok_or_else(|| unknown_column(table, "friction", ROTARY_FRICTION_COLUMNS, "in N·m"))?
            .to_string()
    };
    Ok(super::Mapping {
        velocity,
        friction,
        ..mapping.clone()
    })
}

/// Time columns named with their unit, read in seconds when `--time` is
/// not given and the table has no `t_s`: (name, divisor to seconds).
const TIME_COLUMNS: &[(&str, f64)] = &[
    ("time_s", 1.0),
    ("t_ms", 1e3),
    ("time_ms", 1e3),
    ("t_us", 1e6),
    ("time_us", 1e6),
    ("t_ns", 1e9),
    ("time_ns", 1e9),
    ("stamp_ns", 1e9),
];
/// Time columns without a unit: a table with one of these and no `t_s`
/// is refused rather than read as a steady curve.
const UNITLESS_TIME_COLUMNS: &[&str] = &["t", "time", "timestamp"];

/// `--time` left unset on a table without `t_s`: a steady curve, unless
/// the table has a time column by another name. One named with its unit
/// (`t_ms`, `time_ns`, …) is read in seconds and said in `notes`; one
/// without (`t`, `time`, `timestamp`) is an error that asks for its unit,
/// since a time series fitted as a steady curve would lose its dynamics
/// (pre-sliding, the film's memory) without a word.
fn time_column(
    mapping: super::Mapping,
    table: &super::Table,
    notes: &mut Vec<String>,
) -> Result<super::Mapping, FitError> {
    if mapping.time.is_some() || table.index("t_s").is_some() {
        return Ok(mapping);
    }
    let file = table.source.display().to_string();
    if let Some(&(name, per_s)) = TIME_COLUMNS.iter().find(|(c, _)| table.index(c).is_some()) {
        let time = if per_s == 1.0 {
            name.to_string()
        } else {
            format!("{name} / {per_s:e}")
        };
        notes.push(format!("{file}: the time is `{name}`, read in s: `{time}`"));
        return Ok(super::Mapping {
            time: Some(time),
            ..mapping
        });
    }
    match UNITLESS_TIME_COLUMNS.iter().find(|c| table.index(c).is_some()) {
        Some(name) => Err(FitError::Data {
            what: file,
            message: format!(
                "the table has a time column `{name}` without a unit and no `t_s`: give its unit with --time EXPR in s (`--time {name}` in s, `--time '{name} / 1000'` in ms); a table without a time column is read as a steady curve, each row a steady state (to fit it so, rename the column with --columns)"
            ),
        }),
        None => Ok(mapping),
    }
}

/// Under `--rotary`, no `what` column of the joint's `names` in `table`:
/// the error lists the table's columns and how to name one (`hint`).
fn unknown_column(table: &super::Table, what: &str, names: &[&str], hint: &str) -> FitError {
    FitError::Data {
        what: table.source.display().to_string(),
        message: format!(
            "no {what} column: under --rotary it is read from `{}` when --{what} is not given, and the table has {}; name it with --{what} EXPR, {hint}",
            names.join("`, `"),
            table.names.join(", "),
        ),
    }
}

/// Without `--rotary` and with the default `--velocity`: a table that
/// has no `velocity_m_s` but a joint's velocity column is an error that
/// points at `--rotary`, not one that says `velocity_m_s` is missing.
fn refuse_joint_columns(mapping: &super::Mapping, table: &super::Table) -> Result<(), FitError> {
    let defaults = super::Mapping::default();
    if mapping.velocity != defaults.velocity || table.index(&mapping.velocity).is_some() {
        return Ok(());
    }
    match ROTARY_VELOCITY_COLUMNS
        .iter()
        .find(|(c, _)| table.index(c).is_some())
    {
        Some((joint, _)) => Err(FitError::Data {
            what: table.source.display().to_string(),
            message: format!(
                "the table has a joint's velocity `{joint}` and no `velocity_m_s`: fit a joint with --rotary (velocity in rad/s, deg/s or rpm, friction in N·m; the lever arm is chosen from the data), or name a linear axis's columns with --velocity and --friction"
            ),
        }),
        None => Ok(()),
    }
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
            rotary_columns(&req.mapping, &table, notes)?
        } else {
            refuse_joint_columns(&req.mapping, &table)?;
            req.mapping.clone()
        };
        let mapping = time_column(mapping, &table, notes)?;
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
    let (model_config, contact_scale, model_scale) = model_setup(
        config,
        req.units(),
        choose_scale,
        &train,
        &map_values,
        &key_specs,
        scale,
        &mut notes,
    )?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table::{Delimiter, Table};
    use std::path::Path;

    fn joint_table(header: &str, speeds: &[f64]) -> Table {
        let mut text = format!("{header}\n");
        for v in speeds {
            text += &format!("{v},{}\n", 0.3 + 0.05 * v);
        }
        Table::parse(&text, Path::new("j.csv"), Delimiter::Auto, None, 0).unwrap()
    }

    fn rotary_velocity(header: &str, speeds: &[f64]) -> (Vec<f64>, Vec<String>) {
        let mut notes = Vec::new();
        let table = joint_table(header, speeds);
        let mapping = rotary_columns(&crate::fit::Mapping::default(), &table, &mut notes).unwrap();
        let series = Source::new(table, &mapping).unwrap().series(&[]).unwrap();
        (series.velocity, notes)
    }

    #[test]
    fn a_joints_velocity_in_deg_s_or_rpm_is_read_in_rad_s_and_said() {
        let (rad, notes) = rotary_velocity("velocity_rad_s,torque_nm", &[0.5, 2.0]);
        assert_eq!(rad, vec![0.5, 2.0]);
        assert!(notes.is_empty(), "{notes:?}");
        let (deg, notes) = rotary_velocity("velocity_deg_s,friction_nm", &[90.0, 180.0]);
        approx::assert_relative_eq!(deg[0], std::f64::consts::FRAC_PI_2, epsilon = 1e-12);
        approx::assert_relative_eq!(deg[1], std::f64::consts::PI, epsilon = 1e-12);
        assert!(
            notes[0].contains("`velocity_deg_s`, read as rad/s"),
            "{notes:?}"
        );
        let (rpm, notes) = rotary_velocity("velocity_rpm,friction_nm", &[60.0, 30.0]);
        approx::assert_relative_eq!(rpm[0], 2.0 * std::f64::consts::PI, epsilon = 1e-12);
        approx::assert_relative_eq!(rpm[1], std::f64::consts::PI, epsilon = 1e-12);
        assert!(notes[0].contains("`velocity_rpm`"), "{notes:?}");
    }

    fn time_of(header: &str) -> Result<(Option<String>, Vec<String>), FitError> {
        let mut notes = Vec::new();
        let mut text = format!("{header}\n");
        for k in 0..4 {
            text += &format!("{k},{},1\n", 0.1 * k as f64);
        }
        let table = Table::parse(&text, Path::new("s.csv"), Delimiter::Auto, None, 0).unwrap();
        let m = time_column(crate::fit::Mapping::default(), &table, &mut notes)?;
        Ok((m.time, notes))
    }

    #[test]
    fn a_time_column_named_with_its_unit_is_read_in_seconds_and_said() {
        let (time, notes) = time_of("t_ms,velocity_m_s,friction_n").unwrap();
        assert_eq!(time.as_deref(), Some("t_ms / 1e3"));
        assert!(
            notes[0].contains("the time is `t_ms`, read in s"),
            "{notes:?}"
        );
        let (time, _) = time_of("stamp_ns,velocity_m_s,friction_n").unwrap();
        assert_eq!(time.as_deref(), Some("stamp_ns / 1e9"));
        // `t_s` is the time as it is; no time column is a steady curve.
        assert_eq!(
            time_of("t_s,velocity_m_s,friction_n").unwrap(),
            (None, vec![])
        );
        assert_eq!(
            time_of("n,velocity_m_s,friction_n").unwrap(),
            (None, vec![])
        );
    }

    #[test]
    fn a_time_column_without_a_unit_is_refused_not_read_as_a_steady_curve() {
        let err = time_of("time,velocity_m_s,friction_n")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("time column `time` without a unit")
                && err.contains("--time 'time / 1000'")
                && err.contains("steady curve"),
            "{err}"
        );
        assert!(time_of("t,velocity_m_s,friction_n").is_err());
    }

    #[test]
    fn a_joints_table_without_rotary_is_an_error_that_points_at_rotary() {
        let mapping = crate::fit::Mapping::default();
        let err = refuse_joint_columns(&mapping, &joint_table("velocity_deg_s,torque_nm", &[1.0]))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("`velocity_deg_s`") && err.contains("--rotary"),
            "{err}"
        );
        // A linear axis's table, or a joint's named by --velocity, is read.
        assert!(
            refuse_joint_columns(&mapping, &joint_table("velocity_m_s,friction_n", &[1.0])).is_ok()
        );
        let named = crate::fit::Mapping {
            velocity: "velocity_rad_s * 0.02".into(),
            ..mapping
        };
        assert!(
            refuse_joint_columns(&named, &joint_table("velocity_rad_s,torque_nm", &[1.0])).is_ok()
        );
    }

    #[test]
    fn a_joint_table_without_a_known_column_is_an_error_naming_the_columns_it_has() {
        let table = joint_table("omega,tau", &[1.0]);
        let err = rotary_columns(&crate::fit::Mapping::default(), &table, &mut Vec::new())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("no velocity column")
                && err.contains("`velocity_deg_s`")
                && err.contains("the table has omega, tau")
                && err.contains("--velocity EXPR"),
            "{err}"
        );
        // A joint's column that holds text (a row of units) is named, and
        // reading it says so, not that there is no such column.
        let table = Table::parse(
            "velocity_rad_s,torque_nm\nrad/s,Nm\n1,0.3\n2,0.4\n",
            Path::new("u.csv"),
            Delimiter::Auto,
            None,
            0,
        )
        .unwrap();
        let mapping =
            rotary_columns(&crate::fit::Mapping::default(), &table, &mut Vec::new()).unwrap();
        assert_eq!(mapping.velocity, "velocity_rad_s");
        let Err(err) = Source::new(table, &mapping) else {
            panic!("a column of text was read");
        };
        let err = err.to_string();
        assert!(
            err.contains("holds text") && err.contains("--skip 1"),
            "{err}"
        );
        let table = joint_table("velocity_rad_s,tau", &[1.0]);
        let err = rotary_columns(&crate::fit::Mapping::default(), &table, &mut Vec::new())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("no friction column") && err.contains("`torque_nm`"),
            "{err}"
        );
    }
}
