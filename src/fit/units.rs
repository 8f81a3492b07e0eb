//! The units of a fit's data: a linear axis (m/s, N) or a rotary joint
//! (rad/s, N·m), for every table, column name and message.

/// The units of a fit's data: a linear axis (velocity m/s, friction N) or
/// a rotary joint (rad/s, N·m; `fit --rotary`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Units {
    /// m/s and N.
    #[default]
    Linear,
    /// rad/s and N·m.
    Rotary,
}

impl Units {
    /// The friction's unit.
    pub fn force(self) -> &'static str {
        match self {
            Self::Linear => "N",
            Self::Rotary => "N·m",
        }
    }

    /// The velocity's unit.
    pub fn speed(self) -> &'static str {
        match self {
            Self::Linear => "m/s",
            Self::Rotary => "rad/s",
        }
    }

    /// The friction's unit in a column name (`measured_n`, `measured_n_m`).
    pub fn force_column(self) -> &'static str {
        match self {
            Self::Linear => "n",
            Self::Rotary => "n_m",
        }
    }

    /// The velocity's unit in a column name.
    pub fn speed_column(self) -> &'static str {
        match self {
            Self::Linear => "m_s",
            Self::Rotary => "rad_s",
        }
    }
}
