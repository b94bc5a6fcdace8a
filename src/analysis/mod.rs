//! Analysis: measures computed from placed teeth (no ECS needed), and the report.
//!
//! [`inspect`](mod@inspect) (mesh data and gaps of a case as loaded), [`measures`] (distances,
//! occlusal contacts, IPR limits, Bolton and arch length), [`plot`] (the paper's distance figures)
//! and [`report`] (`orthosim report`: every case under every method, to JSON, CSV, plots and HTML).

pub mod inspect;
pub mod measures;
pub mod plot;
pub mod report;

pub use inspect::{InspectReport, inspect};
pub use report::{ReportOptions, Summary, run_report};
