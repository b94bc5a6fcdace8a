//! Patient cases: the RON schema, the built-in cases, and loading with precise error positions.
//!
//! Every problem in a case file is reported as one line `file:line:column: problem`: syntax errors,
//! unknown fields, unknown or duplicate teeth, non-finite numbers, negative sizes, loads on extracted
//! or absent teeth, absurd load magnitudes. See the guide (`docs/cases.md`) for the schema.

pub mod appliance;
mod parts;
mod values;

use std::path::Path;

use serde::{Deserialize, Serialize};
use thiserror::Error;

pub use parts::{
    CaseBone, CaseConstraint, CaseLoad, CaseOffset, CaseVector, CaseWires, Freedoms, PresentTeeth,
    WireModel,
};
pub use values::{Finite, NonNegative, ToothList, ToothMap};

use super::{fdi::Fdi, import::ImportError, shape::ToothResolution};

/// The built-in cases: name and RON source (embedded in the binary).
pub const BUILTIN_CASES: [(&str, &str); 6] = [
    ("normal", include_str!("../../../assets/cases/normal.ron")),
    ("case1", include_str!("../../../assets/cases/case1.ron")),
    ("case2", include_str!("../../../assets/cases/case2.ron")),
    ("case3", include_str!("../../../assets/cases/case3.ron")),
    ("crowded", include_str!("../../../assets/cases/crowded.ron")),
    (
        "case1-chain",
        include_str!("../../../assets/cases/case1-chain.ron"),
    ),
];

/// Longest case name (characters): the name becomes a file name when a case is exported.
pub const MAX_NAME_CHARS: usize = 120;

/// Largest force accepted on one load (N); orthodontic forces are 0.1–5 N.
pub const MAX_FORCE_N: f32 = 50.0;
/// Largest moment-to-force ratio a load may ask for (mm): past the root's length.
pub const MAX_MF_MM: f32 = 30.0;
/// Largest torque accepted on one load (N·mm); orthodontic moments are up to about 30 N·mm.
pub const MAX_TORQUE_NMM: f32 = 500.0;

/// Largest offset of a tooth from its place in the arch (mm per component).
pub const MAX_OFFSET_MM: f32 = 20.0;
/// Largest offset rotation of a tooth (degrees per component).
pub const MAX_OFFSET_DEG: f32 = 90.0;
/// Largest extra space at one contact (mm).
pub const MAX_SPACE_MM: f32 = 15.0;
/// Largest bite opening (mm).
pub const MAX_BITE_OPENING_MM: f32 = 20.0;

/// A case file that could not be read or is not valid.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum CaseError {
    /// The file could not be read.
    #[error("{path}: cannot read case file: {message}")]
    Io {
        /// The file.
        path: String,
        /// What the system said.
        message: String,
    },
    /// The file is not a valid case; `line` and `column` are 1-based.
    #[error("{path}:{line}:{column}: {message}")]
    Invalid {
        /// The file (or `builtin:NAME`).
        path: String,
        /// Line of the problem.
        line: usize,
        /// Column of the problem.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// A labelled scan could not be read or split, or its teeth not placed.
    #[error("{path}: {message} (named in {case})")]
    Scan {
        /// The scan file(s).
        path: String,
        /// The case file that names it.
        case: String,
        /// What is wrong.
        message: String,
    },
    /// A tooth's mesh file could not be imported.
    #[error("{path}: {message} (tooth {fdi}, named in {case})")]
    Mesh {
        /// The mesh file.
        path: String,
        /// The tooth.
        fdi: Fdi,
        /// The case file that names it.
        case: String,
        /// What is wrong, and where in the mesh.
        message: ImportError,
    },
    /// The name is neither a built-in case nor an existing file.
    #[error(
        "unknown case '{0}': not a built-in case (normal, case1, case2, case3, crowded, case1-chain) nor a .ron file"
    )]
    Unknown(String),
}

/// A patient case as read from RON.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// Short name: 1–[`MAX_NAME_CHARS`] characters, no control characters.
    pub name: String,
    /// What the case shows.
    #[serde(default)]
    pub description: String,
    /// Vertices per procedural tooth (default 125).
    #[serde(default)]
    pub resolution: Option<u32>,
    /// Teeth present in the mouth. Unwritten: all 32, or with `scans`, the teeth the scans label
    /// and `meshes` names.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub teeth: Option<PresentTeeth>,
    /// Extracted teeth (present in the data, hidden, skipped by the simulation).
    #[serde(default)]
    pub extracted: ToothList,
    /// Extra space (mm) opened on the mesial side of a tooth, e.g. a diastema: `{21: 3.0}` opens
    /// 3 mm between 11 and 21. The arch is rebuilt with the space.
    #[serde(default)]
    pub spaces: ToothMap<NonNegative>,
    /// Per-tooth displacements from the arch.
    #[serde(default)]
    pub offsets: ToothMap<CaseOffset>,
    /// A treatment target for `orthosim plan`: each listed tooth's movement from where it stands,
    /// in the same form as `offsets`; unlisted teeth stay. Empty: the plan sets the target up.
    #[serde(default, skip_serializing_if = "ToothMap::is_empty")]
    pub target: ToothMap<CaseOffset>,
    /// Loads.
    #[serde(default)]
    pub loads: Vec<CaseLoad>,
    /// Archwires.
    #[serde(default)]
    pub wire: CaseWires,
    /// Brackets and archwires per arch (the PDL movement model's appliances).
    #[serde(default, skip_serializing_if = "appliance::CaseAppliance::is_empty")]
    pub appliance: appliance::CaseAppliance,
    /// Movement constraints.
    #[serde(default)]
    pub constraints: Vec<CaseConstraint>,
    /// Vertical opening of the bite (mm): the upper arch is raised this far from normal occlusion, as
    /// when teeth are moved with the jaws apart (interdigitated cusps would otherwise lock the arches
    /// against any movement along them). Default 0: the arches in occlusion.
    #[serde(default)]
    pub bite_opening_mm: NonNegative,
    /// Mesh files per tooth (STL, OBJ or PLY), paths relative to the case file, e.g.
    /// `{11: (file: "11.stl")}` or `{11: (file: "11.obj", units: Metres, transform: (translation:
    /// (0.0, 2.0, 0.0)))}`; see [`crate::teeth::import`]. Other teeth are procedural.
    #[serde(default)]
    pub meshes: ToothMap<crate::teeth::import::ToothMeshFile>,
    /// Labelled whole-arch scans, e.g. `[(file: "lower.ply", labels: Property("label"))]`: each
    /// labelled tooth becomes a scanned crown; see [`crate::teeth::import::ScanFile`].
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub scans: Vec<crate::teeth::import::ScanFile>,
    /// Bone meshes, e.g. `(lower: Some((file: "mandible.stl")))`; see [`CaseBone`].
    #[serde(default, skip_serializing_if = "CaseBone::is_empty")]
    pub bone: CaseBone,
}

/// A case with where it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadedCase {
    /// The case.
    pub case: Case,
    /// File path or `builtin:NAME`.
    pub origin: String,
    /// The source text.
    pub source: String,
}

impl Case {
    /// Names of the built-in cases.
    pub fn builtin_names() -> impl Iterator<Item = &'static str> {
        BUILTIN_CASES.iter().map(|(n, _)| *n)
    }

    /// Loads a built-in case by name, or a .ron file by path.
    ///
    /// # Errors
    /// [`CaseError::Unknown`] for a name that is neither; [`CaseError::Io`] for a file that cannot
    /// be read; [`CaseError::Invalid`] with the file, line and column of the first problem (syntax,
    /// unknown field or tooth, a number out of range, a load on an absent tooth…).
    ///
    /// # Example
    /// ```
    /// use orthosim::teeth::{Case, Dentition};
    /// let loaded = Case::resolve("case1")?;
    /// assert_eq!(loaded.origin, "builtin:case1");
    /// let d = Dentition::build(loaded)?;
    /// assert_eq!(d.visible().count(), 28, "first premolars extracted");
    ///
    /// let e = Case::parse("Case(name: \"x\", extracted: [19])", "mine.ron").unwrap_err();
    /// assert!(e.to_string().starts_with("mine.ron:1:"), "{e}");
    /// # Ok::<(), orthosim::teeth::CaseError>(())
    /// ```
    pub fn resolve(name_or_path: &str) -> Result<LoadedCase, CaseError> {
        if let Some((name, src)) = BUILTIN_CASES.iter().find(|(n, _)| *n == name_or_path) {
            return Self::parse(src, &format!("builtin:{name}"));
        }
        let path = Path::new(name_or_path);
        if path.exists() || name_or_path.ends_with(".ron") {
            return Self::load(path);
        }
        Err(CaseError::Unknown(name_or_path.to_owned()))
    }

    /// Reads and validates a case file.
    pub fn load(path: &Path) -> Result<LoadedCase, CaseError> {
        let origin = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| CaseError::Io {
            path: origin.clone(),
            message: e.to_string(),
        })?;
        let source = String::from_utf8(bytes).map_err(|e| {
            let before = &e.as_bytes()[..e.utf8_error().valid_up_to()];
            let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
            let column = before.iter().rev().take_while(|&&b| b != b'\n').count() + 1;
            CaseError::Invalid {
                path: origin.clone(),
                line,
                column,
                message: "file is not valid UTF-8 text".into(),
            }
        })?;
        Self::parse(&source, &origin)
    }

    /// Parses and validates case text; `origin` names it in errors.
    pub fn parse(source: &str, origin: &str) -> Result<LoadedCase, CaseError> {
        let invalid = |line: usize, column: usize, message: String| CaseError::Invalid {
            path: origin.to_owned(),
            line,
            column,
            message,
        };
        if source.trim().is_empty() {
            return Err(invalid(1, 1, "case file is empty".into()));
        }
        // `resolution: 125` and `resolution: Some(125)` both read as Some(125).
        let case: Case = ron::Options::default()
            .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
            .from_str(source)
            .map_err(|e| invalid(e.span.start.line, e.span.start.col, e.code.to_string()))?;
        // With presence from the scans, the checks that need the teeth present wait for the
        // labels (`LoadedCase::check_present`).
        let present = (!case.presence_from_scans()).then(|| case.present());
        case.check(present.as_deref())
            .map_err(|(field, token, message)| {
                let (line, column) = locate(source, field, token.as_deref());
                invalid(line, column, message)
            })?;
        Ok(LoadedCase {
            case,
            origin: origin.to_owned(),
            source: source.to_owned(),
        })
    }

    /// The teeth present in the mouth (extracted ones included). With `scans` and no `teeth`, the
    /// teeth present are only known once the scans are read: see [`Case::present_with`].
    pub fn present(&self) -> Vec<Fdi> {
        self.present_with(&[])
    }

    /// The teeth present, given the teeth the scans label (used when the case has `scans` and
    /// does not write `teeth`: then the teeth present are those labelled or named in `meshes`).
    pub fn present_with(&self, labelled: &[Fdi]) -> Vec<Fdi> {
        Fdi::all()
            .filter(|f| match &self.teeth {
                None if self.presence_from_scans() => {
                    labelled.contains(f) || self.meshes.0.contains_key(f)
                }
                None | Some(PresentTeeth::All) => true,
                Some(PresentTeeth::Only(l)) => l.0.contains(f),
                Some(PresentTeeth::AllBut(l)) => !l.0.contains(f),
            })
            .collect()
    }

    /// True when the teeth present come from the scans' labels (scans and no `teeth`).
    pub fn presence_from_scans(&self) -> bool {
        self.teeth.is_none() && !self.scans.is_empty()
    }

    /// True when the tooth is present and extracted.
    pub fn is_extracted(&self, f: Fdi) -> bool {
        self.extracted.0.contains(&f)
    }

    /// Where a mesh file named in the case is: relative paths are taken from the case file's
    /// folder (from the working folder for a built-in case).
    pub fn mesh_path(origin: &str, file: &str) -> std::path::PathBuf {
        let file = Path::new(file);
        if file.is_absolute() || origin.starts_with("builtin:") {
            return file.to_owned();
        }
        Path::new(origin)
            .parent()
            .map_or_else(|| file.to_owned(), |dir| dir.join(file))
    }

    /// The mesh resolution asked for.
    pub fn tooth_resolution(&self) -> ToothResolution {
        self.resolution
            .map_or(ToothResolution::PAPER, |vertices| ToothResolution {
                vertices,
            })
    }

    /// The wire model of a tooth.
    pub fn wire_of(&self, f: Fdi) -> WireModel {
        self.wire
            .teeth
            .0
            .get(&f)
            .copied()
            .unwrap_or(match f.arch() {
                crate::teeth::fdi::Arch::Upper => self.wire.upper,
                crate::teeth::fdi::Arch::Lower => self.wire.lower,
            })
    }

    /// Cross-field checks: (field, offending token, message); those that need the teeth present
    /// only when `present` is known.
    fn check(&self, present: Option<&[Fdi]>) -> Result<(), (&'static str, Option<String>, String)> {
        let length = self.name.chars().count();
        if !(1..=MAX_NAME_CHARS).contains(&length) {
            return Err((
                "name",
                None,
                format!("the case name must be 1–{MAX_NAME_CHARS} characters, got {length}"),
            ));
        }
        if let Some(c) = self.name.chars().find(|c| c.is_control()) {
            return Err((
                "name",
                None,
                format!(
                    "the case name holds the control character U+{:04X}",
                    u32::from(c)
                ),
            ));
        }
        if let Some(r) = self.resolution
            && !(20..=200_000).contains(&r)
        {
            return Err((
                "resolution",
                Some(r.to_string()),
                format!("resolution must be 20–200000 vertices, got {r}"),
            ));
        }
        if self.bite_opening_mm.0 > MAX_BITE_OPENING_MM {
            return Err((
                "bite_opening_mm",
                None,
                format!(
                    "bite opening of {} mm is beyond the {MAX_BITE_OPENING_MM} mm accepted",
                    self.bite_opening_mm.0
                ),
            ));
        }
        self.check_files()?;
        let Some(present) = present else {
            return Ok(());
        };
        for f in &self.extracted.0 {
            if !present.contains(f) {
                return Err((
                    "extracted",
                    Some(f.to_string()),
                    format!("tooth {f} is extracted but not present"),
                ));
            }
        }
        let absent =
            |field: &'static str, f: &Fdi| -> Result<(), (&'static str, Option<String>, String)> {
                if !present.contains(f) {
                    Err((
                        field,
                        Some(f.to_string()),
                        format!("tooth {f} is not present in this case"),
                    ))
                } else {
                    Ok(())
                }
            };
        for (f, space) in &self.spaces.0 {
            absent("spaces", f)?;
            if space.0 > MAX_SPACE_MM {
                return Err((
                    "spaces",
                    Some(f.to_string()),
                    format!(
                        "space of {} mm at tooth {f} is beyond the {MAX_SPACE_MM} mm accepted",
                        space.0
                    ),
                ));
            }
        }
        for (field, map) in [("offsets", &self.offsets), ("target", &self.target)] {
            let what = if field == "offsets" {
                "offset"
            } else {
                "target movement"
            };
            for (f, offset) in &map.0 {
                absent(field, f)?;
                let (t, r) = (offset.translation, offset.rotation_deg);
                if [t.0, t.1, t.2].iter().any(|c| c.0.abs() > MAX_OFFSET_MM) {
                    let m = format!(
                        "{what} of tooth {f} is beyond the {MAX_OFFSET_MM} mm accepted per axis"
                    );
                    return Err((field, Some(f.to_string()), m));
                }
                if [r.0, r.1, r.2].iter().any(|c| c.0.abs() > MAX_OFFSET_DEG) {
                    let m = format!(
                        "{what} rotation of tooth {f} is beyond the {MAX_OFFSET_DEG}° accepted per axis"
                    );
                    return Err((field, Some(f.to_string()), m));
                }
            }
        }
        for f in self.meshes.0.keys() {
            absent("meshes", f)?;
        }
        for load in &self.loads {
            if load.teeth.0.is_empty() {
                return Err(("loads", None, "a load must name at least one tooth".into()));
            }
            for f in &load.teeth.0 {
                absent("loads", f)?;
                if self.is_extracted(*f) {
                    return Err((
                        "loads",
                        Some(f.to_string()),
                        format!("load on extracted tooth {f}"),
                    ));
                }
            }
            let (fm, tm) = (load.force.magnitude(), load.torque.magnitude());
            if fm > MAX_FORCE_N {
                return Err((
                    "force",
                    None,
                    format!("force of {fm:.1} N is beyond the {MAX_FORCE_N} N accepted"),
                ));
            }
            if tm > MAX_TORQUE_NMM {
                return Err((
                    "torque",
                    None,
                    format!("torque of {tm:.1} N·mm is beyond the {MAX_TORQUE_NMM} N·mm accepted"),
                ));
            }
            if let Some(mf) = load.mf
                && mf.0.abs() > MAX_MF_MM
            {
                return Err((
                    "mf",
                    None,
                    format!(
                        "a moment-to-force ratio of {} mm is beyond the ±{MAX_MF_MM} mm accepted",
                        mf.0
                    ),
                ));
            }
        }
        for c in &self.constraints {
            for f in &c.teeth.0 {
                absent("constraints", f)?;
            }
        }
        for f in self.wire.teeth.0.keys() {
            absent("wire", f)?;
        }
        Ok(())
    }
}

impl Case {
    /// Checks of the mesh and scan file names: (field, offending token, message).
    fn check_files(&self) -> Result<(), (&'static str, Option<String>, String)> {
        use crate::teeth::import::{Labels, MeshFormat};
        for (f, m) in &self.meshes.0 {
            if m.file.trim().is_empty() {
                return Err((
                    "meshes",
                    Some(f.to_string()),
                    format!("the mesh file of tooth {f} is empty"),
                ));
            }
            if let Err(e) = MeshFormat::of(Path::new(&m.file)) {
                return Err(("meshes", Some(m.file.clone()), format!("{}: {e}", m.file)));
            }
        }
        for scan in &self.scans {
            if scan.file.trim().is_empty() {
                return Err(("scans", None, "a scan's file name is empty".into()));
            }
            if let Err(e) = MeshFormat::of(Path::new(&scan.file)) {
                return Err((
                    "scans",
                    Some(scan.file.clone()),
                    format!("{}: {e}", scan.file),
                ));
            }
            match &scan.labels {
                Labels::Json(file) if file.trim().is_empty() => {
                    return Err(("scans", None, "a scan's label file name is empty".into()));
                }
                Labels::Property(name) if name.trim().is_empty() => {
                    return Err((
                        "scans",
                        None,
                        "a scan's label property name is empty".into(),
                    ));
                }
                Labels::Colours(map) if map.is_empty() => {
                    return Err((
                        "scans",
                        Some(scan.file.clone()),
                        format!("the scan {} lists no tooth colours", scan.file),
                    ));
                }
                _ => {}
            }
        }
        Ok(())
    }
}

impl LoadedCase {
    /// The checks that need the teeth present, once the scans' labels are known (cases with
    /// scans and no `teeth`).
    ///
    /// # Errors
    /// [`CaseError::Invalid`] with the position of the first problem.
    pub fn check_present(&self, present: &[Fdi]) -> Result<(), CaseError> {
        self.case
            .check(Some(present))
            .map_err(|(field, token, message)| {
                let (line, column) = locate(&self.source, field, token.as_deref());
                CaseError::Invalid {
                    path: self.origin.clone(),
                    line,
                    column,
                    message,
                }
            })
    }
}

/// 1-based (line, column) of `token` (a whole word) after the field name `field:`; of the field
/// itself when the token is not found; (1, 1) when neither is.
pub fn locate(source: &str, field: &str, token: Option<&str>) -> (usize, usize) {
    let is_word = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let find_word = |from: usize, word: &str| -> Option<usize> {
        let mut start = from;
        while let Some(i) = source[start..].find(word) {
            let at = start + i;
            let before = source[..at].chars().next_back();
            let after = source[at + word.len()..].chars().next();
            if !before.is_some_and(is_word) && !after.is_some_and(is_word) {
                return Some(at);
            }
            start = at + word.len();
        }
        None
    };
    let field_at = find_word(0, field);
    let at = match (field_at, token) {
        (Some(f), Some(t)) => find_word(f, t).or(Some(f)),
        (f, _) => f,
    };
    let Some(at) = at else { return (1, 1) };
    let line = source[..at].matches('\n').count() + 1;
    let column = source[..at]
        .rsplit('\n')
        .next()
        .map_or(0, |l| l.chars().count())
        + 1;
    (line, column)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn optional_numbers_read_with_or_without_some() {
        for src in [
            r#"Case(name: "x", resolution: 300, constraints: [(teeth: [11], max_translation_mm: 2.0)])"#,
            r#"Case(name: "x", resolution: Some(300), constraints: [(teeth: [11], max_translation_mm: Some(2.0))])"#,
        ] {
            let c = Case::parse(src, "t.ron").unwrap().case;
            assert_eq!(c.resolution, Some(300), "{src}");
            assert_eq!(c.constraints[0].max_translation_mm.map(|v| v.0), Some(2.0));
        }
    }

    fn err(src: &str) -> (usize, usize, String) {
        match Case::parse(src, "t.ron") {
            Err(CaseError::Invalid {
                line,
                column,
                message,
                ..
            }) => (line, column, message),
            other => panic!("expected an error, got {other:?}"),
        }
    }

    #[test]
    fn builtin_cases_parse() {
        for name in Case::builtin_names() {
            let c = Case::resolve(name).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(c.case.name, name);
        }
    }

    #[test]
    fn errors_name_line_and_column() {
        let (l, _, m) = err("Case(\n  name: \"x\",\n  extracted: [14, 19],\n)");
        assert_eq!(l, 3, "{m}");
        assert!(m.contains("19"), "{m}");
        let (l, _, m) = err("Case(\n  name: \"x\",\n  extracted: [14, 14],\n)");
        assert_eq!(l, 3);
        assert!(m.contains("duplicate"), "{m}");
        let (l, _, m) = err("Case(\n  name: \"x\",\n  colour: 3,\n)");
        assert_eq!(l, 3);
        assert!(m.contains("colour"), "{m}");
        let (l, c, m) = err(
            "Case(\n  name: \"x\",\n  extracted: [14],\n  loads: [(teeth: [16, 14], force: World(0.0, 0.0, 1.0))],\n)",
        );
        assert_eq!((l, c), (4, 24), "{m}");
        assert!(m.contains("extracted tooth 14"), "{m}");
        let (l, _, m) = err(
            "Case(\n  name: \"x\",\n  loads: [(teeth: [16],\n    force: World(0.0, NaN, 1.0))],\n)",
        );
        assert_eq!(l, 4);
        assert!(m.contains("finite"), "{m}");
        let (l, _, m) = err("Case(\n  name: \"x\",\n  spaces: {21: -2.0},\n)");
        assert_eq!(l, 3);
        assert!(m.contains("negative"), "{m}");
        let (l, _, m) = err("Case(\n  name: \"x\",\n  offsets: {11: (), 11: ()},\n)");
        assert_eq!(l, 3);
        assert!(m.contains("duplicate"), "{m}");
        let (_, _, m) =
            err("Case(name: \"x\", loads: [(teeth: [16], force: World(0.0, 0.0, 1e9))])");
        assert!(m.contains("beyond"), "{m}");
        let (l, c, m) = err(
            "Case(\n  name: \"x\",\n  offsets: {\n    12: (translation: (0.0, 500.0, 0.0)),\n  },\n)",
        );
        assert_eq!((l, c), (4, 5), "{m}");
        assert!(m.contains("beyond"), "{m}");
        let (l, c, m) = err("");
        assert_eq!((l, c), (1, 1));
        assert!(m.contains("empty"));
        let (l, _, _) = err("Case(\n  name: \"x\"\n  extracted: [14],\n)");
        assert_eq!(l, 3, "missing comma");
    }

    #[test]
    fn unknown_names_are_refused() {
        assert!(matches!(Case::resolve("nope"), Err(CaseError::Unknown(_))));
        assert!(matches!(
            Case::resolve("/no/such/file.ron"),
            Err(CaseError::Io { .. })
        ));
    }
}
