//! Treatment planning: a target setup, staging within per-stage limits with no two teeth passing
//! through each other, IPR where they must pass, and the stage meshes aligners are made from.
//!
//! ```no_run
//! use orthosim::planning::{PlanLimits, automatic, plan};
//! use orthosim::teeth::{Case, Dentition};
//! let d = Dentition::build(Case::resolve("crowded")?)?;
//! let limits = PlanLimits::default();
//! let target = automatic(&d, &limits);
//! let p = plan(&d, &target, &limits, 0.0);
//! println!("{} stages, {} IPR contacts", p.stages, p.ipr.len());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! | part | file |
//! |---|---|
//! | limits, sequencing, the limits file | [`limits`] |
//! | the target: from a file or set up automatically | [`target`] |
//! | one arch's automatic set-up | [`setup`] |
//! | canine and molar relations, the anchorage's choice | [`anchorage`] |
//! | one tooth's movement split into stages | [`moves`] |
//! | the collision check of a transition | [`clearance`] |
//! | the stager: sequencing, checks, waits and IPR | [`stager`] |
//! | plan.json and stage meshes | [`export`] |

pub mod anchorage;
pub mod bench;
pub mod clearance;
pub mod export;
pub mod limits;
pub mod moves;
pub mod setup;
pub mod stager;
pub mod target;

pub use limits::{Anchorage, ArchAnchorage, IprLimits, PlanLimits, Sequence, TargetForm};
pub use stager::{Blocked, Plan, PlanIpr, PlanTooth, plan};
pub use target::{Target, automatic, from_offsets};

use thiserror::Error;

/// What can go wrong while planning.
#[derive(Debug, Error)]
pub enum PlanError {
    /// A limits or target file is not valid; `line` and `column` are 1-based.
    #[error("{path}:{line}:{column}: {message}")]
    Invalid {
        /// The file.
        path: String,
        /// Line of the problem.
        line: usize,
        /// Column of the problem.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// An output could not be written.
    #[error(transparent)]
    Output(#[from] crate::io::OutputError),
}
