//! The periodontal-ligament (PDL) movement model: a rigid tooth on a layer of springs over its
//! root below the alveolar crest, loads at the bracket, contact forces between touching teeth,
//! and bone remodelling in clinical time.
//!
//! | file | what |
//! |---|---|
//! | `settings` | [`PdlSettings`]: moduli, thickness, crest depths, bracket height, wire engagement, threshold, remodelling rate, clinical step |
//! | `stiffness` | [`PdlStiffness`]: the 6×6 stiffness over the root triangles (exact for the mesh), the centre of resistance, the compliance, the bilinear initial displacement |
//! | `body` | [`PdlBody`]: a tooth or block for one step; the compliance under its wire and constraints; the twist in clinical time |
//! | `contact` | [`solve_contacts`]: contact forces of all touching teeth together (projected Gauss–Seidel) |
//!
//! Long-term movement (stress-driven remodelling, as Kojima and Fukui's model): per day a tooth
//! moves by β × its initial elastic twist `C w`, shrunk so that the ligament's mean pressure
//! drops by the threshold, where `w` is the wrench of its loads and contact forces about its
//! centre of resistance. Either wire keeps the bracket on its path (`wire_holds_brackets`): the
//! bracket slides along the arch but not across it (buccolingually or vertically), except in the
//! direction of the tooth's own force, which is what the appliance delivers. A rectangular wire
//! also supplies `wire_engagement` of the couple that would stop the tooth turning (about every
//! axis but that of the tooth's own torque), or the couple M/F × F a load asks for; a round wire
//! supplies no couple, so the tooth tips about its bracket.

mod body;
mod contact;
mod settings;
mod stiffness;

pub use body::{PdlBody, blocked, constrained_compliance, engaged, rotated, shifted};
pub use contact::{ContactRow, ContactSolve, SolveParams, solve_contacts};
pub use settings::{CrestDepths, PdlSettings};
pub use stiffness::{
    PdlError, PdlStiffness, ROOT_SAMPLES, RootPoint, centre_of_elasticity, displacement_at,
    root_points, root_samples, stiffness_about, wrench,
};
