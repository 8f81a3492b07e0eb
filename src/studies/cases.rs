//! The cases of each study: docs/model.md §9's table, one function per study.

use super::{fmt_g, steady_key, with, Case, Motion, StudyKind, StudyOptions, FREQUENCIES};
use crate::config::Config;

/// The cases of one study being listed.
struct CaseList<'a> {
    study: StudyKind,
    opts: &'a StudyOptions,
    out: Vec<Case>,
}

impl CaseList<'_> {
    fn push(&mut self, config: Config, motion: Motion, id: String, panel: String, series: String) {
        self.out.push(Case {
            study: self.study,
            steady_key: steady_key(&config),
            id,
            panel,
            series,
            config,
            motion,
            cycles: self.opts.cycles,
        });
    }
}

fn fpanel(f: f64) -> String {
    format!("f = {} Hz", fmt_g(f))
}

/// The transient cases of a study (empty for `stribeck`).
pub fn cases(study: StudyKind, base: &Config, opts: &StudyOptions) -> Vec<Case> {
    let mut list = CaseList {
        study,
        opts,
        out: Vec::new(),
    };
    match study {
        StudyKind::Stribeck => {}
        StudyKind::AmplitudeFrequency => amplitude_frequency(base, &mut list),
        StudyKind::Load => load(base, &mut list),
        StudyKind::Viscosity => viscosity(base, &mut list),
        StudyKind::Inertia => inertia(base, &mut list),
        StudyKind::Unidirectional => unidirectional(base, &mut list),
        StudyKind::Roughness => roughness(base, &mut list),
        StudyKind::Hersey => hersey(base, &mut list),
    }
    list.out
}

fn amplitude_frequency(base: &Config, list: &mut CaseList<'_>) {
    let c = with(base, |c| {
        c.contact.load_n = 20_762.0;
        c.lubricant.viscosity_pa_s = 0.0564;
    });
    for f in FREQUENCIES {
        for v1 in [0.1, 0.5, 1.0] {
            list.push(
                c.clone(),
                Motion {
                    v0: 0.0,
                    v1,
                    f_hz: f,
                },
                format!("v1-{}_f-{}", fmt_g(v1), fmt_g(f)),
                fpanel(f),
                format!("V1 = {} m/s", fmt_g(v1)),
            );
        }
    }
}

fn load(base: &Config, list: &mut CaseList<'_>) {
    for f in FREQUENCIES {
        for load in [5762.0, 10_762.0, 20_762.0] {
            let c = with(base, |c| {
                c.contact.load_n = load;
                c.lubricant.viscosity_pa_s = 0.056;
            });
            list.push(
                c,
                Motion {
                    v0: 0.0,
                    v1: 1.0,
                    f_hz: f,
                },
                format!("load-{}_f-{}", fmt_g(load), fmt_g(f)),
                fpanel(f),
                format!("F = {} N", fmt_g(load)),
            );
        }
    }
}

fn viscosity(base: &Config, list: &mut CaseList<'_>) {
    for f in FREQUENCIES {
        for mu in [0.056, 0.103, 0.143] {
            let c = with(base, |c| {
                c.contact.load_n = 20_762.0;
                c.lubricant.viscosity_pa_s = mu;
            });
            list.push(
                c,
                Motion {
                    v0: 0.0,
                    v1: 1.0,
                    f_hz: f,
                },
                format!("mu-{}_f-{}", fmt_g(mu), fmt_g(f)),
                fpanel(f),
                format!("μ = {} Pa·s", fmt_g(mu)),
            );
        }
    }
}

fn inertia(base: &Config, list: &mut CaseList<'_>) {
    for f in FREQUENCIES {
        for m in [0.1, 1.0, 10.0, 100.0] {
            let c = with(base, |c| {
                c.contact.load_n = 5762.0;
                c.lubricant.viscosity_pa_s = 0.0564;
                c.contact.mass_kg = m;
            });
            list.push(
                c,
                Motion {
                    v0: 0.0,
                    v1: 1.0,
                    f_hz: f,
                },
                format!("m-{}_f-{}", fmt_g(m), fmt_g(f)),
                fpanel(f),
                format!("m = {} kg", fmt_g(m)),
            );
        }
    }
}

fn unidirectional(base: &Config, list: &mut CaseList<'_>) {
    // The text gives no load for Fig. 11; Table A3 says 5 kN: use the
    // nearest text load. V0 = 1, 2, 3 m/s extend the paper's 0.05,
    // 0.25, 0.5 so that the loops reach full film (claim 7).
    let c = with(base, |c| {
        c.contact.load_n = 5762.0;
        c.lubricant.viscosity_pa_s = 0.0564;
    });
    for f in FREQUENCIES {
        for v0 in [0.05, 0.25, 0.5, 1.0, 2.0, 3.0] {
            list.push(
                c.clone(),
                Motion {
                    v0,
                    v1: 0.5 * v0,
                    f_hz: f,
                },
                format!("v0-{}_f-{}", fmt_g(v0), fmt_g(f)),
                fpanel(f),
                format!("V0 = {} m/s", fmt_g(v0)),
            );
        }
    }
}

fn roughness(base: &Config, list: &mut CaseList<'_>) {
    for v0 in [1.0, 0.25] {
        for f in FREQUENCIES {
            for sigma in [2.5e-6, 5e-6, 7.5e-6] {
                let c = with(base, |c| {
                    c.contact.load_n = 20_762.0;
                    c.lubricant.viscosity_pa_s = 0.0564;
                    c.roughness.sigma_m = sigma;
                });
                list.push(
                    c,
                    Motion {
                        v0,
                        v1: 0.5 * v0,
                        f_hz: f,
                    },
                    format!(
                        "v0-{}_sigma-{}_f-{}",
                        fmt_g(v0),
                        fmt_g(sigma * 1e6),
                        fmt_g(f)
                    ),
                    format!("V0 = {} m/s, f = {} Hz", fmt_g(v0), fmt_g(f)),
                    format!("σ = {} µm", fmt_g(sigma * 1e6)),
                );
            }
        }
    }
}

fn hersey(base: &Config, list: &mut CaseList<'_>) {
    // Two groups; inside a group μ·V1/F is the same, so every loop
    // spans the same Hersey-number range.
    // (viscosity Pa·s, load N, V1 m/s, f Hz)
    type Member = (f64, f64, f64, f64);
    let groups: [(&str, [Member; 4]); 2] = [
        (
            "H range ±9.79e-6",
            [
                (0.0564, 5762.0, 1.0, 1.0),
                (0.103, 5762.0 * 0.103 / 0.0564, 1.0, 1.0),
                (0.143, 5762.0 * 0.143 / 0.0564, 1.0, 1.0),
                (0.0564, 5762.0, 1.0, 4.0),
            ],
        ),
        (
            "H range ±2.72e-6",
            [
                (0.0564, 20_762.0, 1.0, 1.0),
                (0.0564, 10_381.0, 0.5, 1.0),
                (0.143, 20_762.0, 0.0564 / 0.143, 1.0),
                (0.0564, 20_762.0, 1.0, 4.0),
            ],
        ),
    ];
    for (g, (panel, members)) in groups.iter().enumerate() {
        for (k, &(mu, load, v1, f)) in members.iter().enumerate() {
            let c = with(base, |c| {
                c.contact.load_n = load;
                c.lubricant.viscosity_pa_s = mu;
            });
            list.push(
                c,
                Motion {
                    v0: 0.0,
                    v1,
                    f_hz: f,
                },
                format!("group-{}_{}", g + 1, k + 1),
                panel.to_string(),
                format!("μ {} F {:.0} V1 {:.3} f {}", fmt_g(mu), load, v1, fmt_g(f)),
            );
        }
    }
}
