//! How a table's columns become a fit's inputs when `--velocity`,
//! `--friction` and `--time` keep their defaults: a joint's columns under
//! `--rotary` (rad/s, deg/s or rpm; N·m or N·mm), a linear axis's velocity
//! and friction named with another unit (mm/s, m/min, mm/min; mN, kN, or
//! `force_n`), a time column named with its
//! unit, the errors that point at what was meant (a joint's table without
//! `--rotary`, a time column without a unit), and the columns a fit does
//! not read, said.

use super::FitError;

/// The column names a joint's table may use for the velocity when
/// `--velocity` keeps its default, each with its factor to rad/s.
const ROTARY_VELOCITY_COLUMNS: &[(&str, f64)] = &[
    ("velocity_rad_s", 1.0),
    ("velocity_deg_s", std::f64::consts::PI / 180.0),
    ("velocity_rpm", std::f64::consts::PI / 30.0),
];
/// The column names a joint's table may use for the friction when
/// `--friction` keeps its default, each with its factor to N·m.
const ROTARY_FRICTION_COLUMNS: &[(&str, f64)] = &[
    ("friction_nm", 1.0),
    ("friction_n_m", 1.0),
    ("torque_nm", 1.0),
    ("torque_n_m", 1.0),
    ("friction_nmm", 1e-3),
    ("friction_n_mm", 1e-3),
    ("torque_nmm", 1e-3),
    ("torque_n_mm", 1e-3),
];

/// `--rotary` with the default column names: a table without
/// `velocity_m_s` / `friction_n` but with a joint's names (`velocity_rad_s`,
/// `velocity_deg_s`, `velocity_rpm`, `friction_nm`, `torque_nm`,
/// `torque_nmm`, …) is read through those, a velocity in deg/s or rpm
/// converted to rad/s and a torque in N·mm to N·m (said in `notes`). A
/// table with none of them is an error that names them.
pub fn rotary_columns(
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
        column_by_unit(table, ROTARY_VELOCITY_COLUMNS, "velocity", "rad/s", notes).ok_or_else(
            || {
                unknown_column(
                    table,
                    "velocity",
                    ROTARY_VELOCITY_COLUMNS,
                    "in rad/s (a column in deg/s: `--velocity 'COLUMN * 0.017453292519943295'`)",
                )
            },
        )?
    };
    let friction = if keeps(&mapping.friction, &defaults.friction) {
        mapping.friction.clone()
    } else {
        column_by_unit(table, ROTARY_FRICTION_COLUMNS, "friction", "N·m", notes)
            .ok_or_else(|| unknown_column(table, "friction", ROTARY_FRICTION_COLUMNS, "in N·m"))?
    };
    Ok(super::Mapping {
        velocity,
        friction,
        ..mapping.clone()
    })
}

/// The first of `columns` (name, factor to `unit`) that `table` has, as the
/// expression that reads it in `unit`; a factor other than 1 is said in
/// `notes` (`what`: the velocity, the friction).
fn column_by_unit(
    table: &super::Table,
    columns: &[(&str, f64)],
    what: &str,
    unit: &str,
    notes: &mut Vec<String>,
) -> Option<String> {
    let &(name, factor) = columns.iter().find(|(c, _)| table.index(c).is_some())?;
    if factor == 1.0 {
        return Some(name.to_string());
    }
    notes.push(format!(
        "{}: the {what} is `{name}`, read as {unit}: `{name} * {factor:e}`",
        table.source.display()
    ));
    Some(format!("{name} * {factor:e}"))
}

/// A linear axis's velocity columns named with a unit other than m/s,
/// read when `--velocity` keeps its default and the table has no
/// `velocity_m_s`, each with its factor to m/s.
const LINEAR_VELOCITY_COLUMNS: &[(&str, f64)] = &[
    ("velocity_mm_s", 1e-3),
    ("velocity_m_min", 1.0 / 60.0),
    ("velocity_mm_min", 1.0 / 60_000.0),
];

/// A linear axis's friction columns named otherwise than `friction_n`,
/// read when `--friction` keeps its default and the table has no
/// `friction_n`, each with its factor to N.
const LINEAR_FRICTION_COLUMNS: &[(&str, f64)] = &[
    ("force_n", 1.0),
    ("friction_mn", 1e-3),
    ("force_mn", 1e-3),
    ("friction_kn", 1e3),
    ("force_kn", 1e3),
];

/// Without `--rotary`: with the default `--velocity` and no `velocity_m_s`
/// in `table`, a linear axis's velocity named with another unit
/// (`velocity_mm_s`, `velocity_m_min`, `velocity_mm_min`) is read in m/s;
/// with the default `--friction` and no `friction_n`, a friction named
/// `force_n`, or with another unit (`friction_mn`, `friction_kn`, …), is
/// read in N; a factor is said in `notes`. Otherwise the column is kept as
/// `mapping` names it.
pub fn linear_columns(
    mapping: &super::Mapping,
    table: &super::Table,
    notes: &mut Vec<String>,
) -> super::Mapping {
    let defaults = super::Mapping::default();
    let by_default = |given: &str, default: &str| given == default && table.index(given).is_none();
    let mut out = mapping.clone();
    if by_default(&mapping.velocity, &defaults.velocity) {
        if let Some(v) = column_by_unit(table, LINEAR_VELOCITY_COLUMNS, "velocity", "m/s", notes) {
            out.velocity = v;
        }
    }
    if by_default(&mapping.friction, &defaults.friction) {
        if let Some(f) = column_by_unit(table, LINEAR_FRICTION_COLUMNS, "friction", "N", notes) {
            out.friction = f;
        }
    }
    out
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
pub fn time_column(
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
fn unknown_column(table: &super::Table, what: &str, names: &[(&str, f64)], hint: &str) -> FitError {
    let names: Vec<&str> = names.iter().map(|(c, _)| *c).collect();
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
pub fn refuse_joint_columns(
    mapping: &super::Mapping,
    table: &super::Table,
) -> Result<(), FitError> {
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

/// Column names a fit reads without being told: a load, temperature or
/// time column by another name is not read.
const DEFAULT_INPUTS: [&str; 3] = ["t_s", "load_n", "temperature_c"];

/// The numeric columns of `table` that no input of `mapping` reads, said
/// in a note: a load, temperature or time column by another name than its
/// default (`load_n`, `temperature_c`, `t_s`) would otherwise be left out
/// without a word.
pub fn unread_columns(mapping: &super::Mapping, table: &super::Table) -> Option<String> {
    let given = [
        mapping.time.as_deref(),
        Some(mapping.velocity.as_str()),
        Some(mapping.friction.as_str()),
        mapping.load.as_deref(),
        mapping.temperature.as_deref(),
    ];
    let read = |name: &str| {
        DEFAULT_INPUTS.contains(&name)
            || given.iter().flatten().any(|e| {
                e.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                    .any(|id| id == name)
            })
    };
    let unread: Vec<&str> = table
        .names
        .iter()
        .map(String::as_str)
        .filter(|n| table.column(n).is_some() && !read(n))
        .collect();
    (!unread.is_empty()).then(|| {
        format!(
            "{}: not read: {} (a load, temperature or time column is read under its default name, `load_n`, `temperature_c`, `t_s`, or named with --load, --temperature, --time)",
            table.source.display(),
            unread.join(", ")
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::Source;
    use crate::table::Table;

    fn joint_table(header: &str, speeds: &[f64]) -> Table {
        let mut text = format!("{header}\n");
        for v in speeds {
            text += &format!("{v},{}\n", 0.3 + 0.05 * v);
        }
        Table::of_csv(&text, "j.csv")
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

    #[test]
    fn a_linear_axis_velocity_in_mm_s_or_m_min_is_read_in_m_s_and_said() {
        let read = |header: &str, speeds: &[f64]| {
            let mut notes = Vec::new();
            let table = joint_table(header, speeds);
            let mapping = linear_columns(&crate::fit::Mapping::default(), &table, &mut notes);
            let series = Source::new(table, &mapping).unwrap().series(&[]).unwrap();
            (series.velocity, notes)
        };
        let (mm, notes) = read("velocity_mm_s,friction_n", &[5.0, 250.0]);
        approx::assert_relative_eq!(mm[0], 5e-3, epsilon = 1e-15);
        approx::assert_relative_eq!(mm[1], 0.25, epsilon = 1e-15);
        assert!(
            notes[0].contains("`velocity_mm_s`, read as m/s"),
            "{notes:?}"
        );
        let (m_min, _) = read("velocity_m_min,friction_n", &[6.0, 12.0]);
        approx::assert_relative_eq!(m_min[0], 0.1, epsilon = 1e-15);
        let (mm_min, _) = read("velocity_mm_min,friction_n", &[600.0, 1200.0]);
        approx::assert_relative_eq!(mm_min[0], 0.01, epsilon = 1e-15);
        // `velocity_m_s` is read as it is, beside any other.
        let table = Table::of_csv(
            "velocity_m_s,velocity_mm_s,friction_n\n0.5,500,1\n",
            "b.csv",
        );
        let mut notes = Vec::new();
        let mapping = linear_columns(&crate::fit::Mapping::default(), &table, &mut notes);
        assert_eq!((mapping.velocity.as_str(), notes), ("velocity_m_s", vec![]));
    }

    #[test]
    fn a_friction_in_mn_kn_or_n_mm_is_read_in_n_or_n_m_and_said() {
        let read = |header: &str, rotary: bool| {
            let mut notes = Vec::new();
            let table = joint_table(header, &[1.0, 2.0]);
            let defaults = crate::fit::Mapping::default();
            let mapping = if rotary {
                rotary_columns(&defaults, &table, &mut notes).unwrap()
            } else {
                linear_columns(&defaults, &table, &mut notes)
            };
            let series = Source::new(table, &mapping).unwrap().series(&[]).unwrap();
            (series.friction, notes)
        };
        // joint_table writes 0.3 + 0.05 v in the friction column.
        let (mn, notes) = read("velocity_m_s,friction_mn", false);
        approx::assert_relative_eq!(mn[1], 0.4e-3, epsilon = 1e-15);
        assert!(
            notes[0].contains("the friction is `friction_mn`, read as N"),
            "{notes:?}"
        );
        let (kn, _) = read("velocity_mm_s,force_kn", false);
        approx::assert_relative_eq!(kn[0], 350.0, epsilon = 1e-9);
        let (n, notes) = read("velocity_m_s,force_n", false);
        assert_eq!((n[0], notes.len()), (0.35, 0));
        let (nmm, notes) = read("velocity_rad_s,torque_nmm", true);
        approx::assert_relative_eq!(nmm[1], 0.4e-3, epsilon = 1e-15);
        assert!(notes[0].contains("`torque_nmm`, read as N·m"), "{notes:?}");
        // `friction_n` is read as it is, beside any other.
        let table = Table::of_csv("velocity_m_s,friction_n,friction_mn\n0.5,1,1000\n", "b.csv");
        let mut notes = Vec::new();
        let mapping = linear_columns(&crate::fit::Mapping::default(), &table, &mut notes);
        assert_eq!((mapping.friction.as_str(), notes), ("friction_n", vec![]));
    }

    fn time_of(header: &str) -> Result<(Option<String>, Vec<String>), FitError> {
        let mut notes = Vec::new();
        let mut text = format!("{header}\n");
        for k in 0..4 {
            text += &format!("{k},{},1\n", 0.1 * k as f64);
        }
        let table = Table::of_csv(&text, "s.csv");
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
    fn the_columns_a_fit_does_not_read_are_said() {
        let table = Table::of_csv(
            "velocity_m_s,friction_n,normal_force_n,load_n,note\n0.1,1,5,5,a\n0.2,1,5,5,b\n",
            "x.csv",
        );
        let mut mapping = crate::fit::Mapping::default();
        let note = unread_columns(&mapping, &table).unwrap();
        // The unread numeric column, not the default load nor a text one.
        assert!(
            note.starts_with("x.csv: not read: normal_force_n ("),
            "{note}"
        );
        mapping.load = Some("2 * normal_force_n".into());
        assert_eq!(unread_columns(&mapping, &table), None);
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
        let table = Table::of_csv(
            "velocity_rad_s,torque_nm\nrad/s,Nm\n1,0.3\n2,0.4\n",
            "u.csv",
        );
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
