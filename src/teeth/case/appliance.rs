//! What a case file says of appliances: each arch's archwire (alloy, section, arch form), its
//! brackets (slot, prescription, which teeth) and the wires that follow it on given days. The
//! mechanics of each are in the appliance module; these are the names a case is written in.

use serde::{Deserialize, Deserializer, Serialize, de};

use super::values::{NonNegative, ToothList};

/// A wire's cross-section, sizes in inches as wires are sold.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum WireSize {
    /// Round wire of this diameter (inches).
    Round(f64),
    /// Rectangular wire: its height across the slot (occluso-gingival, inches) and its width
    /// into the slot (bucco-lingual, inches), e.g. `Rect(0.019, 0.025)`.
    Rect(f64, f64),
}

impl<'de> Deserialize<'de> for WireSize {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        /// The written form, checked before it is a size.
        #[derive(Deserialize)]
        enum Written {
            Round(f64),
            Rect(f64, f64),
        }
        let size = match Written::deserialize(d)? {
            Written::Round(x) => Self::Round(x),
            Written::Rect(h, w) => Self::Rect(h, w),
        };
        size.check().map_err(de::Error::custom)
    }
}

/// Why a wire size is refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SizeError {
    /// A size that is not a positive finite number.
    #[error("wire size {0} is not a positive number of inches")]
    NotPositive(f64),
    /// A size outside the range orthodontic wires come in.
    #[error("wire size {0}\" is outside 0.010–0.030\"")]
    OutOfRange(f64),
}

impl WireSize {
    /// Checks every dimension is a wire's (0.010–0.030 inches).
    ///
    /// # Errors
    /// [`SizeError`] naming the first bad dimension.
    pub fn check(self) -> Result<Self, SizeError> {
        let dims = match self {
            Self::Round(d) => [d, d],
            Self::Rect(h, w) => [h, w],
        };
        for d in dims {
            if !(d.is_finite() && d > 0.0) {
                return Err(SizeError::NotPositive(d));
            }
            if !(0.010..=0.030).contains(&d) {
                return Err(SizeError::OutOfRange(d));
            }
        }
        Ok(self)
    }
}

/// An archwire's alloy.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WireMaterial {
    /// Austenitic stainless steel.
    #[default]
    StainlessSteel,
    /// β-titanium (TMA).
    Tma,
    /// Superelastic nickel–titanium.
    NiTi,
    /// Copper NiTi (thermally activated at mouth temperature): lower plateaus than NiTi.
    CopperNiTi,
}

/// A straight-wire prescription.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Prescription {
    /// McLaughlin, Bennett and Trevisi (1997).
    #[default]
    Mbt,
    /// Roth (1976, 1987).
    Roth,
}

/// A bracket slot size, written as its height in inches: `0.018` or `0.022`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Slot {
    /// 0.018" × 0.025".
    S018,
    /// 0.022" × 0.028".
    #[default]
    S022,
}

impl Slot {
    /// The slot's height (inches), as written.
    pub fn inches(self) -> f64 {
        match self {
            Self::S018 => 0.018,
            Self::S022 => 0.022,
        }
    }
}

impl Serialize for Slot {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_f64(self.inches())
    }
}

impl<'de> Deserialize<'de> for Slot {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = f64::deserialize(d)?;
        [Self::S018, Self::S022]
            .into_iter()
            .find(|s| (s.inches() - v).abs() < 1e-6)
            .ok_or_else(|| {
                de::Error::custom(format!("slot must be 0.018 or 0.022 (inches), got {v}"))
            })
    }
}

/// A preformed arch form.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ArchForm {
    /// Ovoid.
    #[default]
    Ovoid,
    /// Tapered.
    Tapered,
    /// Square.
    Square,
}

/// How the wire is held in each slot: what presses it against the slot's floor, and so part of
/// the friction it slides with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Ligation {
    /// An elastomeric module over the tie wings.
    #[default]
    Elastomeric,
    /// A stainless steel ligature, tied and backed off.
    SteelTie,
    /// A self-ligating bracket whose gate closes the slot without touching the wire.
    PassiveSelfLigating,
    /// A self-ligating bracket whose spring clip presses a full wire into the slot.
    ActiveSelfLigating,
}

impl Ligation {
    /// Every ligation, in the panel's order.
    pub const ALL: [Self; 4] = [
        Self::Elastomeric,
        Self::SteelTie,
        Self::PassiveSelfLigating,
        Self::ActiveSelfLigating,
    ];

    /// As clinicians name it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Elastomeric => "elastomeric",
            Self::SteelTie => "steel tie",
            Self::PassiveSelfLigating => "passive self-ligating",
            Self::ActiveSelfLigating => "active self-ligating",
        }
    }
}

/// What the brackets' slots are made of.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BracketMaterial {
    /// Stainless steel.
    #[default]
    Steel,
    /// Polycrystalline alumina (an aesthetic ceramic bracket).
    Ceramic,
}

impl BracketMaterial {
    /// Every material, in the panel's order.
    pub const ALL: [Self; 2] = [Self::Steel, Self::Ceramic];

    /// As clinicians name it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Steel => "steel",
            Self::Ceramic => "ceramic",
        }
    }
}

/// Each arch's archwire; an arch with none carries no brackets.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseAppliance {
    /// The upper arch's wire.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper: Option<CaseArchWire>,
    /// The lower arch's wire.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower: Option<CaseArchWire>,
    /// Intermaxillary elastics, each from a bonded tooth of one arch to one of the other.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub elastics: Vec<CaseElastic>,
}

/// An intermaxillary elastic worn from `day` between the brackets (or tubes) of `from` and `to`,
/// teeth of opposite arches, rated `force_n` at the stretch it is worn at, e.g. Class II
/// `(from: 13, to: 46, force_n: 1.5)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseElastic {
    /// One end's tooth.
    pub from: super::super::fdi::Fdi,
    /// The other end's tooth, in the other arch.
    pub to: super::super::fdi::Fdi,
    /// Its rated force where worn (N; default 1.5, about 150 g).
    #[serde(default = "coil_force")]
    pub force_n: NonNegative,
    /// Clinical day it is first worn (default 0).
    #[serde(default)]
    pub day: NonNegative,
    /// Clinical day it is last worn (default: to the end).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub until_day: Option<NonNegative>,
}

impl CaseAppliance {
    /// True when neither arch has a wire (and so nothing is bonded).
    pub fn is_empty(&self) -> bool {
        self.upper.is_none() && self.lower.is_none()
    }
}

/// An arch's brackets and the wire engaged in them, e.g.
/// `(material: ni_ti, size: Round(0.014), slot: "0.022", sequence: [(day: 60, material: ni_ti,
/// size: Round(0.018))])`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseArchWire {
    /// The first wire's alloy.
    pub material: WireMaterial,
    /// The first wire's section (inches), e.g. `Round(0.014)` or `Rect(0.019, 0.025)`.
    pub size: WireSize,
    /// Its preformed arch form (default ovoid).
    #[serde(default)]
    pub form: ArchForm,
    /// The brackets' slot (default 0.022").
    #[serde(default)]
    pub slot: Slot,
    /// The brackets' prescription (default MBT).
    #[serde(default)]
    pub prescription: Prescription,
    /// How the wire is tied into the slots (default elastomeric modules).
    #[serde(default)]
    pub ligation: Ligation,
    /// The brackets' material (default stainless steel).
    #[serde(default)]
    pub bracket_material: BracketMaterial,
    /// The coefficient of friction between wire and slot, in place of the one the wire's alloy
    /// and the brackets' material give (e.g. `friction: Some(0.2)`; 0: frictionless).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<NonNegative>,
    /// The wire's ends cinched behind the terminal tubes, so that it cannot slide through them
    /// (default: it slides).
    #[serde(default)]
    pub cinched: bool,
    /// The teeth carrying brackets and tubes (default: every tooth of the arch but third
    /// molars).
    #[serde(default)]
    pub bonded: ToothList,
    /// Later wires, each engaged on its day (clinical days from the start), in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sequence: Vec<WireChange>,
    /// Elastomeric chains along the brackets, each from one bonded tooth to another.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub chains: Vec<CaseChain>,
    /// NiTi coil springs, each hooked between two bonded teeth.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub coils: Vec<CaseCoil>,
}

/// A closed coil pulls its ends together; an open coil pushes them apart.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CoilKind {
    /// Closed coil: space closure.
    #[default]
    Closed,
    /// Open coil: space opening.
    Open,
}

/// A NiTi coil spring placed on `day` between the brackets of `from` and `to`, activated by
/// `activation_mm` (stretched for a closed coil, compressed for an open one), with plateau
/// force `force_n`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseCoil {
    /// One end's tooth.
    pub from: super::super::fdi::Fdi,
    /// The other end's tooth.
    pub to: super::super::fdi::Fdi,
    /// Closed (default) or open.
    #[serde(default)]
    pub kind: CoilKind,
    /// Plateau force (N; default 1.5).
    #[serde(default = "coil_force")]
    pub force_n: NonNegative,
    /// Activation when placed (mm; default 3).
    #[serde(default = "coil_activation")]
    pub activation_mm: NonNegative,
    /// Clinical day it is placed (default 0).
    #[serde(default)]
    pub day: NonNegative,
    /// Power arm on the `from` tooth: the hook's length from the slot towards the root, along
    /// the long axis (mm; default 0, at the slot), so that the force's line passes nearer the
    /// centre of resistance.
    #[serde(default)]
    pub from_arm_mm: NonNegative,
    /// Power arm on the `to` tooth (mm; default 0).
    #[serde(default)]
    pub to_arm_mm: NonNegative,
}

fn coil_force() -> NonNegative {
    NonNegative(1.5)
}

fn coil_activation() -> NonNegative {
    NonNegative(3.0)
}

/// An elastomeric chain placed on `day` over the brackets from tooth `from` to tooth `to`,
/// stretched by `stretch` (its strain when placed: 0.5 is half again its relaxed length).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseChain {
    /// One end's tooth.
    pub from: super::super::fdi::Fdi,
    /// The other end's tooth.
    pub to: super::super::fdi::Fdi,
    /// Strain when placed (default 0.5).
    #[serde(default = "half_stretch")]
    pub stretch: NonNegative,
    /// Clinical day it is placed (default 0).
    #[serde(default)]
    pub day: NonNegative,
    /// Replaced by a fresh chain at the same stretch every this many days, as at each clinical
    /// visit (default: never).
    #[serde(default)]
    pub renew_days: Option<NonNegative>,
    /// Power arm on the `from` tooth: the hook's length from the slot towards the root, along
    /// the long axis (mm; default 0, at the slot), so that the force's line passes nearer the
    /// centre of resistance.
    #[serde(default)]
    pub from_arm_mm: NonNegative,
    /// Power arm on the `to` tooth (mm; default 0).
    #[serde(default)]
    pub to_arm_mm: NonNegative,
}

fn half_stretch() -> NonNegative {
    NonNegative(0.5)
}

/// A wire change: on `day`, the wire is taken out and this one engaged.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WireChange {
    /// Clinical day of the change.
    pub day: NonNegative,
    /// The new wire's alloy.
    pub material: WireMaterial,
    /// The new wire's section.
    pub size: WireSize,
    /// Its arch form (default: the first wire's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub form: Option<ArchForm>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wire(src: &str) -> Result<CaseArchWire, String> {
        ron::from_str(src).map_err(|e| e.to_string())
    }

    #[test]
    fn a_wire_is_written_as_clinicians_name_it_and_defaults_the_rest() {
        let w = wire("(material: ni_ti, size: Round(0.014))").unwrap();
        assert_eq!(
            (w.material, w.size),
            (WireMaterial::NiTi, WireSize::Round(0.014))
        );
        assert_eq!((w.form, w.slot, w.prescription), Default::default());
        assert_eq!(
            (w.ligation, w.bracket_material, w.friction, w.cinched),
            (Ligation::Elastomeric, BracketMaterial::Steel, None, false)
        );
        assert!(w.bonded.0.is_empty() && w.sequence.is_empty());
        let w = wire(
            "(material: stainless_steel, size: Rect(0.019, 0.025), slot: 0.018, form: tapered, \
             sequence: [(day: 30, material: tma, size: Rect(0.017, 0.025))])",
        )
        .unwrap();
        assert_eq!((w.slot, w.form), (Slot::S018, ArchForm::Tapered));
        assert_eq!(w.sequence[0].day.0, 30.0);
        let w = wire(
            "(material: tma, size: Round(0.016), ligation: passive_self_ligating, \
             bracket_material: ceramic, friction: Some(0.2), cinched: true)",
        )
        .unwrap();
        assert_eq!(
            (
                w.ligation,
                w.bracket_material,
                w.friction.map(|f| f.0),
                w.cinched
            ),
            (
                Ligation::PassiveSelfLigating,
                BracketMaterial::Ceramic,
                Some(0.2),
                true
            )
        );
        let w = wire(
            "(material: stainless_steel, size: Rect(0.019, 0.025), \
             chains: [(from: 43, to: 33), (from: 44, to: 42, stretch: 0.8, day: 30)])",
        )
        .unwrap();
        assert_eq!(
            (
                w.chains[0].stretch.0,
                w.chains[0].day.0,
                w.chains[1].stretch.0
            ),
            (0.5, 0.0, 0.8)
        );
        let back: CaseArchWire = ron::from_str(&ron::to_string(&w).unwrap()).unwrap();
        assert_eq!(back, w);
    }

    #[test]
    fn sizes_slots_and_alloys_outside_what_is_made_are_refused_with_their_place() {
        for (src, says) in [
            (
                "(material: ni_ti, size: Round(0.14))",
                "outside 0.010–0.030",
            ),
            (
                "(material: ni_ti, size: Round(NaN))",
                "not a positive number",
            ),
            (
                "(material: ni_ti, size: Rect(0.019, -0.025))",
                "not a positive number",
            ),
            (
                "(material: ni_ti, size: Round(0.014), slot: 0.020)",
                "slot must be 0.018 or 0.022",
            ),
            ("(material: nitinol, size: Round(0.014))", "nitinol"),
            (
                "(material: ni_ti, size: Round(0.014), colour: red)",
                "colour",
            ),
            (
                "(material: ni_ti, size: Round(0.014), chains: [(from: 43, to: 39)])",
                "unknown tooth",
            ),
            (
                "(material: ni_ti, size: Round(0.014), chains: [(from: 43, to: 33, stretch: -1)])",
                "negative",
            ),
            (
                "(material: ni_ti, size: Round(0.014), coils: [(from: 13, to: 16, kind: spring)])",
                "spring",
            ),
            (
                "(material: ni_ti, size: Round(0.014), friction: Some(-0.1))",
                "negative",
            ),
            (
                "(material: ni_ti, size: Round(0.014), ligation: glue)",
                "glue",
            ),
        ] {
            let e = wire(src).unwrap_err();
            assert!(e.contains(says) && e.contains("1:"), "{src}: {e}");
        }
    }
}
