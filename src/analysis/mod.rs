//! Analysis: measures computed from placed teeth (no ECS needed), and the report.
//!
//! [`biomechanics`] (`orthosim validate`: the PDL model beside published numbers),
//! [`inspect`](mod@inspect) (mesh data and gaps of a case as loaded), [`measures`] (distances,
//! occlusal contacts, IPR limits, Bolton and arch length), [`occlusion`] (overjet, overbite and
//! molar relation of the teeth present), [`plot`] (the paper's distance figures)
//! and [`report`] (`orthosim report`: every case under every method, to JSON, CSV, plots and HTML).

pub mod appliance_rows;
pub mod biomechanics;
pub mod bite;
pub mod bite_bench;
pub mod excursion;
pub mod inspect;
pub mod measures;
pub mod occlusal_map;
pub mod occlusion;
pub mod pareto_plot;
pub mod plan_report;
pub mod plot;
pub mod report;

use thiserror::Error;

use crate::{
    io::OutputError, movement::MovementError, sphere_tree::TreeBuildError, teeth::CaseError,
};

pub use biomechanics::{Validation, ValidationRow, validate};
pub use bite::{Bite, BiteContact, bite};
pub use excursion::{Excursion, ExcursionKind, excursion};
pub use inspect::{InspectReport, inspect};
pub use occlusion::{MeasuredOcclusion, measure_occlusion};
pub use report::{ALL_CASES, ReportOptions, Summary, run_report};

/// Why a report could not be made or written.
#[derive(Debug, Error)]
pub enum AnalysisError {
    /// A case could not be read or built.
    #[error(transparent)]
    Case(#[from] CaseError),
    /// A case could not be simulated.
    #[error(transparent)]
    Movement(#[from] MovementError),
    /// Sphere trees could not be built.
    #[error(transparent)]
    Trees(#[from] TreeBuildError),
    /// An output could not or must not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// A plot could not be drawn.
    #[error("cannot draw a plot: {0}")]
    Plot(String),
    /// The summary could not be written as JSON.
    #[error("cannot write the summary as JSON: {0}")]
    Json(String),
}
