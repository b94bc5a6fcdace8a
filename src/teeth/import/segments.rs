//! Labels as real segmentations give them: a tooth's label in pieces, islands of a few
//! triangles, and labels that run past the crown into the gum or along a neighbour.
//!
//! [`tidy_labels`] works on the whole scan before it is split. Each label's largest piece (by
//! area, pieces joined along edges) is the tooth; every other piece of it goes to what it shares
//! most of its border with (another tooth, or the gum). An island of at most [`ISLAND_TRIANGLES`]
//! triangles touching nothing becomes gum; a larger piece touching nothing is left to the repair,
//! which drops loose pieces.
//!
//! [`trim_bleed`] works on one tooth once the scan is placed in orthosim's frame, where the
//! arrangement says which way is occlusal: triangles further below the crown's tip than the
//! anatomy's crown length allows ([`BLEED_HEIGHT`]), or further from the crown's axis than its
//! widest dimension allows ([`BLEED_WIDTH`]; at the neck, below [`BLEED_NECK`] crown lengths,
//! the cervix's), are gum or a neighbour's margin, and are trimmed when they hang from the
//! margin. So are triangles at the neck past the crown's own reach (half its widest anatomical
//! dimension plus [`NEIGHBOUR_SLACK_MM`]) that lie nearer a neighbouring crown's axis than its own, each
//! distance taken in units of that crown's reach: a label that runs along a neighbour's margin
//! would otherwise become a collar inside the neighbour's root.

use std::collections::HashMap;

use glam::Vec3;
use serde::Serialize;

use super::labels::LabelledMesh;
use crate::geometry::TriMesh;
use crate::teeth::{anatomy::ToothAnatomy, fdi::Fdi};

/// Pieces of a label with at most this many triangles are islands, relabelled gum.
pub const ISLAND_TRIANGLES: usize = 8;
/// A crown reaches at most this many times the anatomy's crown length below its tip (plus
/// [`BLEED_SLACK_MM`]).
pub const BLEED_HEIGHT: f32 = 1.3;
/// A crown reaches at most this many times half its widest anatomical dimension from its axis
/// (plus [`BLEED_SLACK_MM`]).
pub const BLEED_WIDTH: f32 = 1.35;
/// Slack (mm) on both limits (twice this at the neck, where the arrangement's axis and the
/// tooth's may part most).
pub const BLEED_SLACK_MM: f32 = 0.75;
/// Below this many crown lengths under the tip, the crown's limit is its cervix's widest
/// dimension rather than its crown's.
pub const BLEED_NECK: f32 = 0.6;

/// Slack (mm) past a crown's own reach before a triangle nearer a neighbour's axis is the
/// neighbour's.
pub const NEIGHBOUR_SLACK_MM: f32 = 0.25;

/// A neighbouring crown as the trim sees it: a point on its axis (the centre of its upper half,
/// orthosim's frame) and its reach from that axis (half its widest anatomical dimension, mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrownAxis {
    /// A point on the axis.
    pub at: Vec3,
    /// Half the crown's widest anatomical dimension (mm).
    pub reach: f32,
}

impl CrownAxis {
    /// The axis of raw crown `mesh` (orthosim's frame) whose occlusal direction is `occlusal`:
    /// the centre of its vertices within half a crown length of its tip (which bleeding at the
    /// margin does not reach). `None` for an empty mesh.
    pub fn of(mesh: &TriMesh, an: &ToothAnatomy, occlusal: Vec3) -> Option<Self> {
        if mesh.vertices.is_empty() {
            return None;
        }
        let mut heights: Vec<f32> = mesh.vertices.iter().map(|v| v.dot(occlusal)).collect();
        heights.sort_by(f32::total_cmp);
        // The tip: high, but not a lone spike.
        let tip = heights[((heights.len() - 1) as f32 * 0.99) as usize];
        let (sum, n) = mesh
            .vertices
            .iter()
            .filter(|v| v.dot(occlusal) >= tip - 0.5 * an.crown_length)
            .fold((Vec3::ZERO, 0usize), |(s, n), v| (s + *v, n + 1));
        (n > 0).then(|| Self {
            at: sum / n as f32,
            reach: 0.5 * an.mesiodistal.max(an.buccolingual),
        })
    }

    /// Distance of `p` from this axis across `occlusal`, in units of the reach.
    fn relative(&self, p: Vec3, occlusal: Vec3) -> f32 {
        let d = p - self.at;
        (d - occlusal * d.dot(occlusal)).length() / self.reach.max(1e-3)
    }
}

/// One change to a scan's labels.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LabelFix {
    /// The label it had (FDI number).
    pub label: u8,
    /// What was done: `"moved"` (a second piece given to what it touches), `"dropped"` (an
    /// island of a few triangles given to what it touches, or to the gum), `"trimmed"`
    /// (triangles past the crown left out).
    pub action: &'static str,
    /// Where it went: an FDI number, or 0 for the gum.
    pub to: u8,
    /// Triangles changed.
    pub triangles: usize,
    /// Their centre (mm; in orthosim's frame once the scan is placed).
    pub at: [f32; 3],
}

/// Relabels the second pieces and islands of each label (see the module doc), and says what it
/// changed.
pub fn tidy_labels(scan: &mut LabelledMesh) -> Vec<LabelFix> {
    let mesh = &scan.mesh;
    let n = mesh.triangles.len().min(scan.labels.len());
    // Vertices welded by position, so files that repeat corners per triangle still connect.
    let mut canon: HashMap<[u32; 3], u32> = HashMap::new();
    let ids: Vec<u32> = mesh
        .vertices
        .iter()
        .enumerate()
        .map(|(i, v)| {
            *canon
                .entry(v.to_array().map(f32::to_bits))
                .or_insert(i as u32)
        })
        .collect();
    let mut by_edge: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    for t in 0..n {
        for e in edges_of(mesh, &ids, t) {
            by_edge.entry(e).or_default().push(t as u32);
        }
    }
    let mut fixes = Vec::new();
    // One piece at a time, smallest first, the pieces found again after each change: a piece
    // given to its neighbour can join that neighbour's other pieces.
    for _ in 0..n.max(1) {
        let pieces = label_pieces(&scan.labels, n, &by_edge, &scan.mesh, &ids);
        let Some(fix) = next_fix(scan, &pieces, &by_edge, &ids) else {
            break;
        };
        fixes.push(fix);
    }
    fixes
}

/// The pieces of each label (triangles joined along edges): the piece of each triangle
/// (`u32::MAX` for gum), and each piece's label and triangles.
type Pieces = (Vec<u32>, Vec<(Fdi, Vec<usize>)>);

fn label_pieces(
    labels: &[Option<Fdi>],
    n: usize,
    by_edge: &HashMap<(u32, u32), Vec<u32>>,
    mesh: &TriMesh,
    ids: &[u32],
) -> Pieces {
    let mut piece = vec![u32::MAX; n];
    let mut pieces: Vec<(Fdi, Vec<usize>)> = Vec::new();
    for start in 0..n {
        let Some(label) = labels[start] else {
            continue;
        };
        if piece[start] != u32::MAX {
            continue;
        }
        let id = pieces.len() as u32;
        piece[start] = id;
        let mut members = vec![start];
        let mut k = 0;
        while k < members.len() {
            let t = members[k];
            k += 1;
            for e in edges_of(mesh, ids, t) {
                for &o in &by_edge[&e] {
                    let o = o as usize;
                    if piece[o] == u32::MAX && labels[o] == Some(label) {
                        piece[o] = id;
                        members.push(o);
                    }
                }
            }
        }
        pieces.push((label, members));
    }
    (piece, pieces)
}

/// Relabels the smallest piece that is not its label's largest (by area) and has somewhere to
/// go, and says what was done; `None` when every label is one piece (or its other pieces touch
/// nothing and are more than islands).
fn next_fix(
    scan: &mut LabelledMesh,
    (piece, pieces): &Pieces,
    by_edge: &HashMap<(u32, u32), Vec<u32>>,
    ids: &[u32],
) -> Option<LabelFix> {
    let mesh = &scan.mesh;
    let area = |members: &[usize]| -> f64 {
        members
            .iter()
            .map(|&t| {
                let [a, b, c] = mesh.triangle(t).map(|v| v.as_dvec3());
                (b - a).cross(c - a).length()
            })
            .sum()
    };
    let areas: Vec<f64> = pieces.iter().map(|(_, m)| area(m)).collect();
    let mut largest: HashMap<Fdi, usize> = HashMap::new();
    for (i, (label, _)) in pieces.iter().enumerate() {
        let best = largest.entry(*label).or_insert(i);
        if areas[i] > areas[*best] {
            *best = i;
        }
    }
    let mut order: Vec<usize> = (0..pieces.len())
        .filter(|&i| largest[&pieces[i].0] != i)
        .collect();
    order.sort_by_key(|&i| (pieces[i].1.len(), i));
    for i in order {
        let (label, members) = &pieces[i];
        // What the piece borders, by shared edges.
        let mut border: HashMap<Option<Fdi>, usize> = HashMap::new();
        for &t in members {
            for e in edges_of(mesh, ids, t) {
                for &o in &by_edge[&e] {
                    let o = o as usize;
                    if piece[o] != i as u32 {
                        *border.entry(scan.labels[o]).or_default() += 1;
                    }
                }
            }
        }
        let most = border
            .iter()
            .max_by_key(|(to, count)| (**count, to.map_or(0, Fdi::number)))
            .map(|(to, _)| *to);
        let island = members.len() <= ISLAND_TRIANGLES;
        let (to, action) = match most {
            Some(to) => (to, if island { "dropped" } else { "moved" }),
            None if island => (None, "dropped"),
            None => continue,
        };
        let centre = members
            .iter()
            .map(|&t| {
                let [a, b, c] = mesh.triangle(t);
                (a + b + c) / 3.0
            })
            .sum::<Vec3>()
            / members.len() as f32;
        let fix = LabelFix {
            label: label.number(),
            action,
            to: to.map_or(0, Fdi::number),
            triangles: members.len(),
            at: centre.to_array(),
        };
        for &t in members {
            scan.labels[t] = to;
        }
        return Some(fix);
    }
    None
}

/// The three edges of triangle `t` as welded vertex pairs.
fn edges_of(mesh: &TriMesh, ids: &[u32], t: usize) -> [(u32, u32); 3] {
    let tri = mesh.triangles[t].map(|v| ids.get(v as usize).copied().unwrap_or(v));
    [0, 1, 2].map(|k| {
        let (a, b) = (tri[k], tri[(k + 1) % 3]);
        (a.min(b), a.max(b))
    })
}

/// Leaves out the triangles of tooth `fdi`'s raw crown `mesh` (orthosim's frame) with a corner
/// past the crown (see the module doc) that hang from an opening of the surface (a spike inside
/// the crown is the repair's); `occlusal` is the tooth's occlusal direction and `neighbours` the
/// axes of the crowns beside it in the arch. The fix says what was trimmed, `None` when nothing
/// was.
pub fn trim_bleed(
    mesh: &TriMesh,
    fdi: Fdi,
    an: &ToothAnatomy,
    occlusal: Vec3,
    neighbours: &[CrownAxis],
) -> (TriMesh, Option<LabelFix>) {
    if mesh.vertices.is_empty() || mesh.triangles.is_empty() {
        return (mesh.clone(), None);
    }
    let mut heights: Vec<f32> = mesh.vertices.iter().map(|v| v.dot(occlusal)).collect();
    heights.sort_by(f32::total_cmp);
    // The tip: high, but not a lone spike.
    let tip = heights[((heights.len() - 1) as f32 * 0.99) as usize];
    let floor = tip - BLEED_HEIGHT * an.crown_length - BLEED_SLACK_MM;
    let Some(own) = CrownAxis::of(mesh, an, occlusal) else {
        return (mesh.clone(), None);
    };
    let axis = own.at;
    let own_limit = (own.reach + NEIGHBOUR_SLACK_MM) / own.reach.max(1e-3);
    // The crown is widest at its contacts and narrows to the cervix: below the upper part the
    // limit is the cervix's.
    let reach = 0.5 * BLEED_WIDTH * an.mesiodistal.max(an.buccolingual) + BLEED_SLACK_MM;
    let neck = tip - BLEED_NECK * an.crown_length;
    let reach_neck = 0.5 * BLEED_WIDTH * an.mesiodistal_cervix.max(an.buccolingual_cervix)
        + 2.0 * BLEED_SLACK_MM;
    let past = |p: Vec3| {
        let d = p - axis;
        let across = d - occlusal * d.dot(occlusal);
        let height = p.dot(occlusal);
        let limit = if height < neck {
            reach_neck.min(reach)
        } else {
            reach
        };
        let relative = own.relative(p, occlusal);
        height < floor
            || across.length() > limit
            || (height < neck
                && relative > own_limit
                && neighbours
                    .iter()
                    .any(|n| n.relative(p, occlusal) < relative))
    };
    let mut kept = Vec::with_capacity(mesh.triangles.len());
    let (mut cut, mut sum) = (0usize, Vec3::ZERO);
    let beyond: Vec<bool> = mesh.vertices.iter().map(|&p| past(p)).collect();
    let cut_here = reaching_the_margin(mesh, |t| {
        mesh.triangles[t].iter().any(|&v| beyond[v as usize])
    });
    for (t, tri) in mesh.triangles.iter().enumerate() {
        if cut_here[t] {
            let [a, b, c] = mesh.triangle(t);
            cut += 1;
            sum += (a + b + c) / 3.0;
        } else {
            kept.push(*tri);
        }
    }
    if cut == 0 {
        return (mesh.clone(), None);
    }
    let fix = LabelFix {
        label: fdi.number(),
        action: "trimmed",
        to: 0,
        triangles: cut,
        at: (sum / cut as f32).to_array(),
    };
    (
        TriMesh::new(mesh.vertices.clone(), kept).without_unused_vertices(),
        Some(fix),
    )
}

/// The triangles for which `past` holds that are joined (through such triangles, along shared
/// vertices) to an opening of the surface: what bled past the crown hangs from its margin, while
/// a spike's fan or a pit inside the crown does not.
fn reaching_the_margin(mesh: &TriMesh, past: impl Fn(usize) -> bool) -> Vec<bool> {
    let n = mesh.triangles.len();
    let mut uses: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut by_vertex: HashMap<u32, Vec<usize>> = HashMap::new();
    let mut queue = Vec::new();
    let mut reached = vec![false; n];
    for t in (0..n).filter(|&t| past(t)) {
        let tri = mesh.triangles[t];
        for v in tri {
            by_vertex.entry(v).or_default().push(t);
        }
        let open = (0..3).any(|k| {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            uses[&(a.min(b), a.max(b))] == 1
        });
        if open {
            reached[t] = true;
            queue.push(t);
        }
    }
    while let Some(t) = queue.pop() {
        for v in mesh.triangles[t] {
            for &o in &by_vertex[&v] {
                if !reached[o] {
                    reached[o] = true;
                    queue.push(o);
                }
            }
        }
    }
    reached
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::teeth::{anatomy::anatomy, fdi::Arch, fdi::ToothKind};

    /// A flat strip of `n` × 2 quads, each quad's two triangles labelled by `label(column)`.
    fn strip(n: usize, label: impl Fn(usize) -> Option<Fdi>) -> LabelledMesh {
        let mut mesh = TriMesh::default();
        for i in 0..=n {
            for j in 0..3 {
                mesh.vertices.push(Vec3::new(i as f32, j as f32, 0.0));
            }
        }
        let mut labels = Vec::new();
        for i in 0..n as u32 {
            for j in 0..2u32 {
                let (a, b) = (3 * i + j, 3 * (i + 1) + j);
                mesh.triangles.push([a, b, b + 1]);
                mesh.triangles.push([a, b + 1, a + 1]);
                labels.extend([label(i as usize); 2]);
            }
        }
        LabelledMesh { mesh, labels }
    }

    #[test]
    fn second_pieces_go_to_what_they_touch_and_islands_to_the_gum() {
        let (a, b) = (Fdi::new(11).ok(), Fdi::new(21).ok());
        // 11 on columns 0–4, 21 on 5–11 but column 8 carries 11's label; gum beyond.
        let mut scan = strip(14, |c| match c {
            8 => a,
            0..=4 => a,
            5..=11 => b,
            _ => None,
        });
        // A loose island of two triangles labelled 21, far away.
        let base = scan.mesh.vertices.len() as u32;
        scan.mesh.vertices.extend([
            Vec3::new(50.0, 0.0, 0.0),
            Vec3::new(51.0, 0.0, 0.0),
            Vec3::new(51.0, 1.0, 0.0),
            Vec3::new(50.0, 1.0, 0.0),
        ]);
        scan.mesh
            .triangles
            .extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
        scan.labels.extend([b, b]);
        let fixes = tidy_labels(&mut scan);
        assert_eq!(fixes.len(), 2, "{fixes:?}");
        let moved = fixes.iter().find(|f| f.label == 11).unwrap();
        assert_eq!((moved.to, moved.triangles), (21, 4));
        assert_eq!(moved.action, "dropped", "four triangles are an island");
        let island = fixes.iter().find(|f| f.label == 21).unwrap();
        assert_eq!((island.to, island.action), (0, "dropped"));
        assert!(scan.labels[8 * 4..9 * 4].iter().all(|l| *l == b));
        assert!(
            scan.labels[scan.labels.len() - 2..]
                .iter()
                .all(Option::is_none)
        );
        // Nothing left to tidy.
        assert!(tidy_labels(&mut scan).is_empty());
    }

    /// An open column of 12-sided rings (height, radius), joined by quads, open at both ends.
    fn column(rings: &[(f32, f32)]) -> TriMesh {
        let mut mesh = TriMesh::default();
        let sides = 12u32;
        for &(y, r) in rings {
            for k in 0..sides {
                let a = k as f32 / sides as f32 * std::f32::consts::TAU;
                mesh.vertices.push(Vec3::new(r * a.cos(), y, r * a.sin()));
            }
        }
        for ring in 0..rings.len() as u32 - 1 {
            for k in 0..sides {
                let (a, b) = (ring * sides + k, ring * sides + (k + 1) % sides);
                mesh.triangles.push([a, b, b + sides]);
                mesh.triangles.push([a, b + sides, a + sides]);
            }
        }
        mesh
    }

    #[test]
    fn a_label_run_into_the_gum_is_trimmed_back_to_the_crown() {
        let an = anatomy(Arch::Lower, ToothKind::CentralIncisor);
        let fdi = Fdi::new(41).unwrap();
        // A crown-sized column of quads from y = 0 to the crown length, and a flap of gum from
        // its foot out to 8 mm at 2 mm below it.
        let mesh = column(&[(an.crown_length, 2.0), (0.0, 2.5), (-2.0, 8.0)]);
        let (trimmed, fix) = trim_bleed(&mesh, fdi, &an, Vec3::Y, &[]);
        let fix = fix.expect("the flap is trimmed");
        assert_eq!((fix.action, fix.label), ("trimmed", 41));
        assert_eq!(
            fix.triangles, 24,
            "every triangle with a corner on the flap"
        );
        let reach = trimmed
            .vertices
            .iter()
            .map(|v| Vec3::new(v.x, 0.0, v.z).length())
            .fold(0.0, f32::max);
        assert!(reach <= 2.5 + 1e-5, "{reach}");
        // A crown with nothing past it is left as it is, and so is one whose cap has a spike
        // (the repair smooths spikes; they hang from no opening).
        let mut crown = TriMesh::new(mesh.vertices.clone(), mesh.triangles[..24].to_vec());
        assert!(trim_bleed(&crown, fdi, &an, Vec3::Y, &[]).1.is_none());
        crown
            .vertices
            .push(Vec3::new(9.0, an.crown_length + 0.5, 0.0));
        crown
            .triangles
            .extend((0..12u32).map(|k| [36, (k + 1) % 12, k]));
        assert!(trim_bleed(&crown, fdi, &an, Vec3::Y, &[]).1.is_none());
    }

    #[test]
    fn a_label_run_along_a_neighbour_is_trimmed_on_the_neighbours_side_only() {
        let an = anatomy(Arch::Lower, ToothKind::CentralIncisor);
        let fdi = Fdi::new(41).unwrap();
        // A crown-sized column and, 2 mm below it, a flap 3.5 mm out all round: within the
        // neck's own limit, but past the crown's reach where a neighbour stands 6 mm away.
        let reach = 0.5 * an.mesiodistal.max(an.buccolingual);
        let flap = reach + 0.5;
        let mesh = column(&[(an.crown_length, 2.0), (0.0, 2.5), (-2.0, flap)]);
        // Alone, the flap is the crown's.
        assert!(trim_bleed(&mesh, fdi, &an, Vec3::Y, &[]).1.is_none());
        let neighbour = CrownAxis {
            at: Vec3::new(reach + 3.0, an.crown_length, 0.0),
            reach,
        };
        let (trimmed, fix) = trim_bleed(&mesh, fdi, &an, Vec3::Y, &[neighbour]);
        let fix = fix.expect("the flap under the neighbour is trimmed");
        assert_eq!((fix.action, fix.label), ("trimmed", 41));
        assert!(fix.at[0] > 0.0, "{:?}", fix.at);
        // Nothing of the flap is left on the neighbour's side, all of it on the other side.
        let low: Vec<Vec3> = trimmed
            .vertices
            .iter()
            .copied()
            .filter(|v| v.y < -1.0)
            .collect();
        assert!(low.iter().all(|v| v.x < 0.5 * flap), "{low:?}");
        assert_eq!(low.iter().filter(|v| v.x < -1.0).count(), 5, "{low:?}");
        // A neighbour far off leaves it alone.
        let far = CrownAxis {
            at: Vec3::new(30.0, 0.0, 0.0),
            reach,
        };
        assert!(trim_bleed(&mesh, fdi, &an, Vec3::Y, &[far]).1.is_none());
    }
}
