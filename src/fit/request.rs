//! A calibration as data and its flow, read top-down: what was asked
//! ([`FitRequest`]: the data and how to read them, the keys, how to search,
//! whether to fit the classic models), and [`FitRequest::run`], the one
//! flow the command line and Python both call:
//!
//! ```text
//! prepare (data, scale, keys)  →  select (--fit auto's terms)  →  fit ours
//!   →  the fitted file  →  the classic models  →  the report
//! ```
//!
//! Each caller prints its own progress (the lines come through a callback)
//! and its own summary; the files are written here, each when it is
//! complete (the fitted file before the classic models start).

use super::candidates::initial_specs;
use super::compare::{fit_baselines, fit_ours, OursFitted};
use super::confirm::Fallback;
use super::driver::FitOutcome;
use super::inputs::DataRequest;
use super::offset_try;
use super::options::{LabelledProgress, SearchSettings};
use super::prepare::prepare;
use super::prepared::Prepared;
use super::select::{select_terms, Selection};
use super::{FitError, ParamSpec};
use crate::config::Config;
use crate::interrupt::Stop;
use crate::text::Num;
use std::path::PathBuf;

/// Everything a calibration needs besides the base configuration.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FitRequest {
    /// The data and how to read them.
    pub data: DataRequest,
    /// Fitted parameters with their optional bounds and starts (`auto`
    /// among them: the data choose the terms).
    pub params: Vec<ParamSpec>,
    /// How each model's fit searches.
    pub search: SearchSettings,
    /// Also fit Coulomb + viscous, Stribeck and LuGre.
    pub baselines: bool,
}

/// Where a calibration writes: the fitted parameter file and the report
/// folder (each optional; checked before any computation).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FitOutputs {
    /// The fitted parameter file (complete; written atomically).
    pub fitted: Option<PathBuf>,
    /// The report folder: `summary.md`, `fit.csv`, plots, one folder per
    /// classic model.
    pub report: Option<PathBuf>,
}

/// What a calibration found.
pub struct Calibration {
    /// The data and our model as prepared (notes, scales, the contact's gain).
    pub prepared: Prepared,
    /// `--fit auto`'s selection.
    pub selection: Option<Selection>,
    /// Our fit.
    pub ours: OursFitted,
    /// The classic models' fits (with `baselines`).
    pub classic: Vec<FitOutcome>,
    /// The classic models skipped, each with why.
    pub skipped: Vec<String>,
    /// The fitted parameter file's text.
    pub yaml: String,
    /// With the classic models: which model predicts best, in a sentence
    /// (the summary's first lines).
    pub verdict: String,
    /// The sections after ours in the summary: the selection's and (with
    /// the classic models) the models table and their errors by direction.
    pub extra_md: String,
    /// The files of the report, when one was written.
    pub report_files: Vec<PathBuf>,
}

impl Calibration {
    /// Our summary with every section (what `summary.md` holds).
    pub fn summary_md(&self) -> String {
        super::report::summary(&self.ours.outcome, &self.verdict, &self.extra_md)
    }
}

impl FitRequest {
    /// The ranges the command line enforces.
    pub fn check(&self) -> Result<(), FitError> {
        self.data.check()?;
        if self.params.is_empty() {
            return Err(FitError::Data {
                what: "--fit".into(),
                message: "no parameter to fit".into(),
            });
        }
        self.search.check()
    }

    /// The calibration: prepare → select → fit ours → the fitted file →
    /// the classic models → the report. `progress` receives every line
    /// (labelled `fit` for the flow's own, else by the model fitted);
    /// `stop` ends the work at its next evaluation, with
    /// [`FitError::Interrupted`] (a report folder made here is removed, a
    /// fitted file already written stays).
    pub fn run(
        &self,
        config: &Config,
        outputs: &FitOutputs,
        progress: Option<&LabelledProgress>,
        stop: &Stop,
    ) -> Result<Calibration, FitError> {
        let say = |l: &str| {
            if let Some(p) = progress {
                p("fit", l)
            }
        };
        self.check()?;
        // Outputs are checked before any computation; a report folder made
        // here is removed again if the fit fails or is stopped.
        if let Some(o) = &outputs.fitted {
            drop(crate::output::AtomicFile::create(o)?);
        }
        let report_dir = outputs
            .report
            .as_deref()
            .map(crate::output::prepare_output_dir)
            .transpose()?;
        let (mut p, mut selection, mut ours) = self.ours_selected(config, progress, stop, &say)?;
        let offset_md = self.offset_tried(
            config,
            &mut p,
            &mut selection,
            &mut ours,
            progress,
            stop,
            &say,
        )?;
        let mut extra_md = selection.as_ref().map_or(String::new(), |s| {
            let md = super::selection_report::report(s, p.data.units);
            if offset_md.is_empty() {
                md
            } else {
                md + "\n" + &offset_md
            }
        });
        extra_md.insert_str(0, &range_and_inertia(&p, &mut ours, &say));
        let yaml = super::report::fitted_yaml(&ours.config, &ours.outcome, &p.names, &ours.map);
        if let Some(o) = &outputs.fitted {
            crate::output::write_file(o, yaml.as_bytes())?;
            // Said at once: a stop during the classic models keeps it.
            say(&format!("wrote {} (complete)", o.display()));
        }
        let Classics {
            classic,
            skipped,
            verdict,
            report_files,
        } = self.classics_and_report(&p, &ours, &mut extra_md, outputs, progress, stop, &say)?;
        if let Some(d) = report_dir {
            d.keep();
        }
        Ok(Calibration {
            prepared: p,
            selection,
            ours,
            classic,
            skipped,
            yaml,
            verdict,
            extra_md,
            report_files,
        })
    }
}

/// The report's first sections: the range the calibration saw (also
/// attached to the fitted file) and, when the residual follows the
/// acceleration, that warning (also said).
fn range_and_inertia(p: &Prepared, ours: &mut OursFitted, say: &dyn Fn(&str)) -> String {
    let gain = p.contact_scale.as_ref().map_or(1.0, |s| s.gain);
    let mut md = super::calibrated_range::attach(&mut ours.config, &ours.outcome, gain);
    if let Some(w) = super::inertia_check::inertia_warning(&ours.outcome) {
        say(&w);
        md.insert_str(
            0,
            &format!("## The residual and the acceleration\n\n{w}\n\n"),
        );
    }
    md
}

impl FitRequest {
    /// The data prepared, `--fit auto`'s selection (with `auto`) and our
    /// fit, confirmed on the selection's folds.
    fn ours_selected(
        &self,
        config: &Config,
        progress: Option<&LabelledProgress>,
        stop: &Stop,
        say: &(dyn Fn(&str) + Sync),
    ) -> Result<(Prepared, Option<Selection>, OursFitted), FitError> {
        // With `auto`: the base key and the names given; the selection adds
        // terms to them.
        let (auto, given, specs) = initial_specs(&self.params);
        let mut p = prepare(config, &self.data, &specs, auto)?;
        for n in &p.notes {
            say(n);
        }
        let mut selection = if auto {
            Some(select_terms(&mut p, &given, &self.search, say, stop)?)
        } else {
            None
        };
        let ours = self.fit_confirmed(&mut p, &given, selection.as_mut(), progress, stop, say)?;
        Ok((p, selection, ours))
    }

    /// Rule 12 (`offset_try.rs`): where the direction asymmetry was chosen
    /// on a time series with no map fitted, the calibration again with an
    /// offset fitted as a map; where the offset pays, that calibration
    /// replaces `p`, `selection` and `ours`. Returns the selection section's
    /// paragraph on it (empty where the rule does not apply).
    #[allow(clippy::too_many_arguments)] // the flow's state, handed on once
    fn offset_tried(
        &self,
        config: &Config,
        p: &mut Prepared,
        selection: &mut Option<Selection>,
        ours: &mut OursFitted,
        progress: Option<&LabelledProgress>,
        stop: &Stop,
        say: &(dyn Fn(&str) + Sync),
    ) -> Result<String, FitError> {
        let Some((data, params)) =
            offset_try::with_offset(&self.data, &self.params, p, selection.as_ref())
        else {
            return Ok(String::new());
        };
        let alt = FitRequest {
            data,
            params,
            ..self.clone()
        };
        let units = p.data.units;
        say("auto: the direction asymmetry was chosen on a time series, which vanishes at rest where an offset stays: the calibration runs again with an offset fitted as a map (rule 12)");
        let with_offset = |l: &str| say(&format!("(with the offset) {l}"));
        let (p2, s2, o2) = match alt.ours_selected(config, progress, stop, &with_offset) {
            Ok(t) => t,
            Err(FitError::Interrupted(i)) => return Err(FitError::Interrupted(i)),
            Err(e) => {
                let why = e.to_string();
                say(&format!("auto: the offset could not be weighed: {why}"));
                return Ok(offset_try::paragraph(None, Some(&why), units));
            }
        };
        // The request keeps `auto`, so the run again has its selection.
        let Some(s2) = s2 else {
            return Ok(String::new());
        };
        let v = offset_try::weigh(ours, &o2, &s2);
        if let Some(v) = &v {
            say(&format!(
                "auto: the offset {} (CV RMS {} with it, {} without; fitted at {})",
                if v.kept {
                    "pays and is kept"
                } else {
                    "does not pay"
                },
                Num::sig(v.cv_with, 5),
                Num::sig(v.cv_without, 5),
                Num::sig(v.offset, 5),
            ));
            if v.kept {
                *p = p2;
                *selection = Some(s2);
                *ours = o2;
            }
        }
        Ok(offset_try::paragraph(v.as_ref(), None, units))
    }
}

impl FitRequest {
    /// Our fit; under `--fit auto` (`selection`) cross-validated on the
    /// selection's folds and confirmed there (`confirm.rs`): a chosen set
    /// that does not pay at its final optimum over the best set with one
    /// term fewer, or holds two terms confounded at that optimum, gives way
    /// to that set (or the lighter set of the two), which is fitted in its
    /// place.
    fn fit_confirmed(
        &self,
        p: &mut Prepared,
        given: &[ParamSpec],
        mut selection: Option<&mut Selection>,
        progress: Option<&LabelledProgress>,
        stop: &Stop,
        say: &dyn Fn(&str),
    ) -> Result<OursFitted, FitError> {
        let cross_validated = self.baselines || selection.is_some();
        // The last fallback taken: the larger set's fit and selection.
        let mut last: Option<(OursFitted, Selection, Fallback)> = None;
        loop {
            say(&format!(
                "{} parameter(s) on {} file(s) ({} validation), {} local run(s), {} global points",
                p.model.parameters_len() + p.map_fit.len(),
                p.data.train.len(),
                p.data.validate.len(),
                self.search.starts,
                self.search.global_points
            ));
            let ours = fit_ours(p, &self.search, progress, stop, cross_validated)?;
            let Some(s) = selection.as_deref_mut() else {
                return Ok(ours);
            };
            let units = p.data.units;
            let (ours, fallback) = match last.take() {
                Some((larger, before, f)) => {
                    match kept_larger(p, given, s, larger, ours, before, &f, say)? {
                        // The larger set again: only a flag may still move it.
                        Weighed::Larger(larger) => {
                            let f = larger.outcome.fold_mse.as_deref().and_then(|m| {
                                let flags = super::trial::flags_of(&larger.outcome);
                                super::confirm::confounded_at_final(s, m, flags, units)
                            });
                            (larger, f)
                        }
                        Weighed::Smaller(ours) => {
                            let f = fallback_of(s, &ours, units);
                            (ours, f)
                        }
                    }
                }
                None => {
                    let f = fallback_of(s, &ours, units);
                    (ours, f)
                }
            };
            let Some(f) = fallback else {
                return Ok(ours);
            };
            say(&format!("auto: not confirmed: {}", f.why));
            let before = s.clone();
            super::confirm::fall_back(p, given, s, f.clone())?;
            last = Some((ours, before, f));
        }
    }
}

/// The set a final fit `ours` of `s.chosen` falls back to, if any
/// (`confirm.rs`): the folds' verdict first, then a flag.
fn fallback_of(s: &Selection, ours: &OursFitted, units: super::Units) -> Option<Fallback> {
    let m = ours.outcome.fold_mse.as_deref()?;
    super::confirm::unconfirmed(s, m, units).or_else(|| {
        let flags = super::trial::flags_of(&ours.outcome);
        super::confirm::confounded_at_final(s, m, flags, units)
    })
}

/// Which of two final fits a fallback leaves.
enum Weighed {
    /// The fallback was overturned: the larger set stays.
    Larger(OursFitted),
    /// The fallback stands.
    Smaller(OursFitted),
}

/// After the fallback `f` from the set of `before` (fitted as `larger`)
/// was fitted as `smaller`: which stays. When the fallback is overturned
/// (`Fallback::overturned`), `s` and `p`'s model are the larger set's again.
#[allow(clippy::too_many_arguments)] // the confirmation's state, handed on once
fn kept_larger(
    p: &mut Prepared,
    given: &[ParamSpec],
    s: &mut Selection,
    larger: OursFitted,
    smaller: OursFitted,
    before: Selection,
    f: &Fallback,
    say: &dyn Fn(&str),
) -> Result<Weighed, FitError> {
    let folds = (&larger.outcome.fold_mse, &smaller.outcome.fold_mse);
    let (Some(l), Some(m)) = folds else {
        return Ok(Weighed::Smaller(smaller));
    };
    let Some(why) = f.overturned(&before, l, m, p.data.units) else {
        return Ok(Weighed::Smaller(smaller));
    };
    say(&format!("auto: kept: {why}"));
    let o = &larger.outcome;
    let optimum = o.params.iter().map(|q| q.name.clone());
    let optimum = optimum.zip(o.best.iter().copied()).collect();
    super::confirm::keep_larger(p, given, s, before, &optimum, why)?;
    Ok(Weighed::Larger(larger))
}

/// What follows our fit: the classic models, the verdict, the report's files.
struct Classics {
    classic: Vec<FitOutcome>,
    skipped: Vec<String>,
    verdict: String,
    report_files: Vec<PathBuf>,
}

impl FitRequest {
    /// The classic models on the same data (when asked), the models
    /// section and verdict appended to `extra_md`, and the report folder
    /// written (when asked).
    #[allow(clippy::too_many_arguments)] // the flow's state, handed on once
    fn classics_and_report(
        &self,
        p: &Prepared,
        ours: &OursFitted,
        extra_md: &mut String,
        outputs: &FitOutputs,
        progress: Option<&LabelledProgress>,
        stop: &Stop,
        say: &dyn Fn(&str),
    ) -> Result<Classics, FitError> {
        let (classic, skipped) = if self.baselines {
            fit_baselines(p, &self.search, progress, stop)?
        } else {
            (Vec::new(), Vec::new())
        };
        for s in &skipped {
            say(s);
        }
        let verdict = if self.baselines {
            extra_md.push_str(&super::models_table::models_section(
                &ours.outcome,
                &classic,
            ));
            super::models_table::verdict(&ours.outcome, &classic)
        } else {
            String::new()
        };
        let mut report_files = Vec::new();
        if let Some(r) = &outputs.report {
            report_files =
                super::report::write_models_report(r, &ours.outcome, &classic, &verdict, extra_md)?;
            say(&format!(
                "report in {} ({} files)",
                r.display(),
                report_files.len()
            ));
        }
        Ok(Classics {
            classic,
            skipped,
            verdict,
            report_files,
        })
    }
}

/// The spec a bound or start of `name` applies to: a fitted parameter's,
/// or under `--fit auto` one of a key the selection may choose (made on
/// first use, marked [`ParamSpec::if_chosen`]).
fn spec_for<'a>(
    specs: &'a mut Vec<ParamSpec>,
    name: &str,
    flag: &str,
) -> Result<&'a mut ParamSpec, FitError> {
    if let Some(i) = specs.iter().position(|s| s.name == name) {
        return Ok(&mut specs[i]);
    }
    let auto = specs.iter().any(|s| s.name == super::candidates::AUTO);
    if auto && super::candidates::may_choose(name) {
        specs.push(ParamSpec {
            name: name.to_string(),
            if_chosen: true,
            ..Default::default()
        });
        return Ok(specs.last_mut().expect("just pushed"));
    }
    let message = if auto {
        format!(
            "`{name}` is neither in --fit nor a key --fit auto may choose ({})",
            super::candidates::choosable_keys().join(", ")
        )
    } else {
        format!("`{name}` is not in --fit")
    };
    Err(if flag == "--bounds" {
        FitError::Bounds {
            key: name.to_string(),
            message,
        }
    } else {
        FitError::Data {
            what: format!("{flag} {name}"),
            message,
        }
    })
}

/// Fitted parameters from names, `(name, lo, hi)` bounds and `(name,
/// start)` starts; every bound and start must name a fitted parameter or,
/// under `--fit auto`, a key the selection may choose (used if chosen).
pub fn param_specs(
    keys: &[String],
    bounds: &[(String, f64, f64)],
    starts: &[(String, f64)],
) -> Result<Vec<ParamSpec>, FitError> {
    let mut specs: Vec<ParamSpec> = Vec::new();
    for k in keys {
        let k = k.trim();
        if k.is_empty() {
            return Err(FitError::Key {
                key: String::new(),
                message: "an empty name in the list".into(),
            });
        }
        if specs.iter().any(|s| s.name == k) {
            return Err(FitError::Key {
                key: k.into(),
                message: "named twice".into(),
            });
        }
        specs.push(ParamSpec {
            name: k.to_string(),
            ..Default::default()
        });
    }
    for (n, lo, hi) in bounds {
        spec_for(&mut specs, n, "--bounds")?.bounds = Some((*lo, *hi));
    }
    for (n, v) in starts {
        let s = spec_for(&mut specs, n, "--start")?;
        if !v.is_finite() {
            return Err(FitError::Data {
                what: format!("--start {n}"),
                message: format!("`{v}` is not a finite number"),
            });
        }
        s.start = Some(*v);
    }
    Ok(specs)
}
