//! Configuration: one YAML format for everything, in the ROS 2
//! parameter-file shape.
//!
//! ```yaml
//! friction_node:            # the node name (or /**)
//!   ros__parameters:
//!     contact:
//!       load_n: 20762.0
//! ```
//!
//! Every key carries its SI unit in its name. Every default equals the
//! paper's Tables A2–A4 and `docs/model.md` (they are taken from the physics
//! core's `Default` impls, so there is one source of truth).
//! `launch-config/default.yaml` documents every key; it is embedded in the
//! binary and used when no `--config` is given.
//!
//! Unknown keys are rejected with their full dotted name; values outside
//! their physical range are rejected with the key, the value and the range
//! ([`Config::validate`]). Overrides `dotted.key=value` are applied to the
//! YAML tree before it is read, so they are checked exactly like file keys.
//!
//! | file | content |
//! |---|---|
//! | `model.rs` | the model's sections (`contact`, `texture`, `lubricant`, `roughness`, `solver`) |
//! | `node_sections.rs` | the node's sections (`node`, `ros`, `iceoryx2`, `recording`) |
//! | `load.rs` | parameter files, their ROS 2 shapes, `--set` overrides |
//! | `validate.rs` | physical ranges of the model's sections, one function per section; the range checks |
//! | `validate_node.rs` | ranges and names of the node's sections (`node`, `ros`, `iceoryx2`, `recording`), the snapshot ring's memory |
//! | `ros_names.rs` | the ROS 2 naming rules for topics, node names and namespaces |
//! | `contacts.rs` | `contacts.*`: several contacts, each overriding the top-level sections |
//! | `calibrated_range.rs` | where a fitted file was calibrated ([`CalibratedRange`]): speeds by direction, loads, temperatures, the training error |
//! | `error.rs` | [`ConfigError`] and the [`Origin`] of a configuration |
//! | `nearest_key.rs` | the valid name a misspelt or unit-less key most likely meant |
//! | `envelope.rs` | the inputs every entry point accepts: velocity, load, temperature ([`Envelope`]) |
//! | `parameters.rs` | the live-parameter catalogue (declared keys, types, ranges, writability) and [`parameters::apply_set`] |
//! | `topics.rs` | the node's ROS 2 topic names resolved from the configuration (namespace, `~/`, remappings) |
//! | `ros_args.rs` | `--ros-args` as rcl parses them (a `launch_ros` Node action) |
//! | `tests.rs` | unit tests of loading, overrides and validation |

mod calibrated_range;
mod contacts;
mod envelope;
mod error;
mod load;
mod model;
pub mod nearest_key;
mod node_sections;
pub mod parameters;
pub mod ros_args;
mod ros_names;
pub mod topics;
mod validate;
mod validate_node;

pub use calibrated_range::{CalibratedRange, RangeSide};
pub use contacts::{
    ContactEntry, ContactList, ContactSolverConfig, OutputPlan, ResolvedContact, CONTACT_SECTIONS,
    MAX_CONTACTS, MAX_JOINT_NAME_BYTES, SINGLE_CONTACT_NAME,
};
pub use envelope::{
    Envelope, InputLimits, OutOfEnvelope, ViscosityLaw, TEMPERATURE_RANGE_C, VISCOSITY_RANGE_PA_S,
};
pub use error::{ConfigError, Origin};
pub use load::apply_override;
pub use model::*;
pub use node_sections::*;
pub use ros_args::RosArgs;
pub use ros_names::{check_namespace, check_node_name, check_topic};
pub use validate::{key_ranges, IntervalText, KeyRange};
pub use validate_node::snapshot_bytes;

use crate::physics::{
    Contact, Geometry, Lubricant, Method, ModelParams, Pocket, Profile, ReferenceSettings,
    Roughness, SolverSettings, TimeScheme,
};
use serde::{Deserialize, Serialize};
use serde_norway::Value;

/// The shipped default parameter file (also the documentation of every key).
pub const DEFAULT_YAML: &str = include_str!("../../launch-config/default.yaml");

/// Top-level keys accepted as the node entry of a parameter file.
pub const DEFAULT_NODE_NAME: &str = "friction_node";

/// The whole configuration (the `ros__parameters` mapping).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Config {
    /// Follow `/clock` (`rosgraph_msgs/msg/Clock`) instead of the wall clock
    /// in timer mode, as ROS 2 nodes do for simulation and bag playback.
    pub use_sim_time: bool,
    /// The `contact` section.
    pub contact: ContactConfig,
    /// `texture`: rectangular pockets, as parallel arrays (none by default)
    pub texture: TextureConfig,
    /// The `lubricant` section.
    pub lubricant: LubricantConfig,
    /// The `roughness` section.
    pub roughness: RoughnessConfig,
    /// The `solver` section.
    pub solver: SolverConfig,
    /// `drivetrain`: losses beside the contact, added to its friction (all 0: the contact alone)
    pub drivetrain: DrivetrainConfig,
    /// `node`: the fixed-step loop (friction-node run)
    pub node: NodeConfig,
    /// The `ros` section.
    pub ros: RosConfig,
    /// `iceoryx2`: zero-copy shared-memory IPC on one host.
    pub iceoryx2: Iceoryx2Config,
    /// `recording`: MCAP, ROS 2 profile (run --record FILE enables it)
    pub recording: RecordingConfig,
    /// `calibrated_range`: where the one contact was calibrated (written
    /// by `fit`; absent: not watched).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub calibrated_range: Option<CalibratedRange>,
    /// Several contacts, each overriding the top-level sections (last, so
    /// that a top-level mistake is reported first).
    #[serde(skip_serializing_if = "ContactList::is_empty")]
    pub contacts: ContactList,
}

impl Config {
    /// The physics core's parameters.
    pub fn model(&self) -> ModelParams {
        let c = &self.contact;
        let t = &self.texture;
        ModelParams {
            geometry: Geometry {
                length: c.length_m,
                width: c.width_m,
                profile: match c.profile {
                    ProfileKind::Parabolic => Profile::Parabolic {
                        depth: c.profile_depth_m,
                    },
                    ProfileKind::Linear => Profile::Linear {
                        depth: c.profile_depth_m,
                    },
                    ProfileKind::Flat => Profile::Flat,
                },
                pockets: (0..t.pocket_start_m.len())
                    .map(|i| Pocket {
                        start: t.pocket_start_m[i],
                        width: t.pocket_width_m[i],
                        depth: t.pocket_depth_m[i],
                    })
                    .collect(),
            },
            lubricant: Lubricant {
                viscosity: self.lubricant.viscosity_pa_s,
                density: self.lubricant.density_kg_m3,
                gas_viscosity: self.lubricant.gas_viscosity_pa_s,
                gas_density: self.lubricant.gas_density_kg_m3,
                ambient_pressure: self.lubricant.ambient_pressure_pa,
                saturation_pressure: self.lubricant.saturation_pressure_pa,
                vapour_pressure: self.lubricant.vapour_pressure_pa,
                vapour_fraction_saturation: self.lubricant.vapour_fraction_at_saturation,
                vapour_fraction_vapour: self.lubricant.vapour_fraction_at_vapour_pressure,
            },
            roughness: Roughness {
                sigma: self.roughness.sigma_m,
                asperity_density: self.roughness.asperity_density_per_m2,
                asperity_radius: self.roughness.asperity_radius_m,
                effective_modulus: self.roughness.effective_modulus_pa,
                flow_factors: self.roughness.flow_factors,
                lay_gamma: self.roughness.lay_gamma,
            },
            contact: Contact {
                mass: c.mass_kg,
                min_film: c.min_film_m,
            },
            terms: self.terms(),
        }
    }

    /// The contact's friction terms (the `contact` and `drivetrain`
    /// sections' term keys).
    // A test build's list has a test term without YAML: it takes its default.
    #[allow(clippy::needless_update)]
    fn terms(&self) -> crate::physics::FrictionTerms {
        use crate::physics::terms::boundary_film::BoundaryFilm;
        let c = &self.contact;
        let d = &self.drivetrain;
        crate::physics::FrictionTerms {
            boundary_film: BoundaryFilm {
                friction: c.boundary_friction,
                sign_regularization: c.sign_regularization_m_s,
            },
            boundary_rate: crate::physics::BoundaryRate {
                sensitivity: c.boundary_friction_rate,
                activation_speed: c.boundary_activation_speed_m_s,
            },
            presliding: crate::physics::Presliding {
                stiffness: c.presliding_stiffness_n_m,
                damping: c.presliding_damping_n_s_m,
            },
            soft_width: crate::physics::WidthLaw {
                exponent: c.width_load_exponent,
                reference_load: c.width_reference_load_n,
            },
            drivetrain: crate::physics::Drivetrain {
                coulomb: d.coulomb_n,
                viscous: d.viscous_n_s_m,
                viscous_exponent: d.viscous_exponent,
                viscous_reference_speed: d.viscous_reference_speed_m_s,
                load_coefficient: d.load_coefficient,
                quadratic: d.quadratic_n_s2_m2,
                coulomb_asymmetry: d.coulomb_asymmetry_n,
                stribeck: d.stribeck_n,
                stribeck_speed: d.stribeck_speed_m_s,
                stribeck_exponent: d.stribeck_exponent,
            },
            ..Default::default()
        }
    }

    /// How the liquid's viscosity follows the temperature.
    pub fn viscosity_model(&self) -> crate::physics::ViscosityModel {
        match self.lubricant.viscosity_model {
            ViscosityModelKind::Constant => crate::physics::ViscosityModel::Constant,
            ViscosityModelKind::Vogel => {
                crate::physics::ViscosityModel::Vogel(crate::physics::VogelModel {
                    b_c: self.lubricant.vogel_b_c,
                    c_c: self.lubricant.vogel_c_c,
                })
            }
        }
    }

    /// The solver's settings.
    pub fn solver_settings(&self) -> SolverSettings {
        let s = &self.solver;
        let r = &s.reference;
        SolverSettings {
            cells: s.cells,
            dt: s.dt_s,
            method: match s.method {
                MethodKind::Newton => Method::Newton,
                MethodKind::Reference => Method::Reference,
            },
            scheme: match s.scheme {
                SchemeKind::Bdf2 => TimeScheme::Bdf2,
                SchemeKind::Theta => TimeScheme::Theta {
                    theta1: s.theta1,
                    theta2: s.theta2,
                },
            },
            tolerance: s.tolerance,
            max_iterations: s.max_iterations,
            flux: s.flux.couette_flux(),
            reference: ReferenceSettings::from(r),
        }
    }

    /// The resolved configuration as a ROS 2 parameter file.
    pub fn to_yaml(&self) -> String {
        let mut root = serde_norway::Mapping::new();
        let mut node = serde_norway::Mapping::new();
        node.insert(
            Value::String("ros__parameters".into()),
            serde_norway::to_value(self).expect("config serializes"),
        );
        root.insert(
            Value::String(DEFAULT_NODE_NAME.into()),
            Value::Mapping(node),
        );
        serde_norway::to_string(&Value::Mapping(root)).expect("config serializes")
    }
}

#[cfg(test)]
mod tests;
