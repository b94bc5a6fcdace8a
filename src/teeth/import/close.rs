//! Closing a cleaned surface into a solid: holes filled, the margin given a root, and the places
//! where the surface meets itself cut out and closed again.
//!
//! A scan's small self-intersections (folds near the margin or a hole) and any place where a
//! closing meets the crown are repaired the same way: the crown's triangles in the crossing pairs
//! (for a crossing between generated triangles, the crown triangles they hang from), with one ring
//! of neighbours, are removed, and the surface is closed again. At most [`MAX_CUTS`] rounds and
//! [`RepairLimits::max_cut_fraction`] of the triangles; the
//! exact self-intersection check decides, so the result is always a closed, manifold surface that
//! does not meet itself, or an error saying where it still does.

use std::collections::{HashMap, HashSet};

use glam::{IVec3, Vec3};

use super::{
    MARGIN_COS,
    error::{ImportError, Near},
    fill::fill_hole,
    occlusal_direction,
    repair::{self, RepairLimits, Repairs, RootReport},
    root, sweep,
    template::{self, NoTemplate, Template},
};
use crate::geometry::{MeshError, TriMesh};
use crate::teeth::fdi::Fdi;

/// Rounds of cutting out self-intersecting patches before giving up. A scan-resolution crown
/// whose jagged margin needs the star-shaped collar can take more than ten: each round cuts only
/// a few edges (at least [`CUT_RADIUS_MM`]) around the crossings it finds.
pub const MAX_CUTS: usize = 24;
/// Rounds of trimming a folded margin before building the root on what is left.
pub const MAX_TRIMS: usize = 16;
/// The cervical margin of a crown is at least this many times as long as the crown's largest
/// extent (the neck of a tooth is open all round; a hole elsewhere is shorter).
pub const MARGIN_SPAN: f32 = 1.0;
/// A cut reaches this many mean edge lengths from each crossing...
pub const CUT_RADIUS_EDGES: f32 = 1.5;
/// ...and at least this far (mm).
pub const CUT_RADIUS_MM: f32 = 0.3;
/// Crossing pairs gathered per round.
const MAX_PAIRS: usize = 4096;

/// A closed tooth surface.
pub(super) struct Closed {
    /// The solid, outward.
    pub mesh: TriMesh,
    /// The margin's centroid, when a root was generated.
    pub cervical: Option<Vec3>,
    /// The root's apical direction (unit), when a root was generated.
    pub apical: Option<Vec3>,
    /// The crown's anatomical orientation (world), when a template was fitted to it: the
    /// fitted template's rotation before its root was turned away from the neighbours'.
    pub crown_rotation: Option<glam::Quat>,
}

/// Which root a scanned crown gets.
#[derive(Clone, Copy, Debug)]
pub(super) enum RootChoice {
    /// The tooth type's template fitted to the crown, starting from the tooth's pose in the
    /// arrangement when known, then turned and shortened as the guide says.
    Template(super::RootGuide),
    /// A cone along the margin's normal.
    Cone,
}

/// Closes `crown` (clean, consistently wound, possibly open) into a solid, trimming a folded
/// margin for at most `max_trims` rounds first.
pub(super) fn close(
    mut crown: TriMesh,
    fdi: Fdi,
    root_length: f32,
    limits: &RepairLimits,
    repairs: &mut Repairs,
    choice: RootChoice,
    max_trims: usize,
) -> Result<Closed, ImportError> {
    // The template and its fit, once the margin is known (None: the cone, and why).
    let mut fitted: Option<Result<(std::sync::Arc<Template>, template::Fit), NoTemplate>> = None;
    let budget = (limits.max_cut_fraction * crown.triangles.len() as f32) as usize;
    let (mut trims, mut round) = (0, 0);
    loop {
        let loops = repair::boundary_loops(&crown)?;
        let lengths: Vec<f32> = loops
            .iter()
            .map(|l| repair::loop_length(&crown, l))
            .collect();
        // The longest opening is the margin when it is as long as the surface is wide (a crown
        // is open all round its neck) and beyond the hole limit; every other one is a hole.
        let extent = repair::used_span(&crown);
        let margin = (0..loops.len())
            .max_by(|&a, &b| lengths[a].total_cmp(&lengths[b]))
            .filter(|&i| lengths[i] > limits.max_hole_mm && lengths[i] >= MARGIN_SPAN * extent);
        let mut base = crown.clone();
        let mut holes = Vec::new();
        for (i, l) in loops.iter().enumerate() {
            if Some(i) != margin {
                fill_hole(&mut base, l);
                holes.push(lengths[i]);
            }
        }
        if let Some(m) = margin {
            let (centre, apical) = root::margin_axis(&base, &loops[m])?;
            if apical.dot(-occlusal_direction(fdi.arch())) < MARGIN_COS {
                return Err(ImportError::OpenNotMargin {
                    length_mm: lengths[m],
                    at: Near(crown.vertices[loops[m][0] as usize]),
                    max_hole_mm: limits.max_hole_mm,
                });
            }
            if fitted.is_none() {
                fitted = Some(match choice {
                    RootChoice::Cone => Err(NoTemplate::NotAsked),
                    RootChoice::Template(guide) => {
                        let t = Template::of(fdi.arch(), fdi.kind());
                        match template::fit(&base, fdi, guide.guess, centre, apical) {
                            Some(f) => f
                                .usable(centre, guide.guess)
                                .map(|()| (t, guide.applied_to(f))),
                            None => Err(NoTemplate::TooFew),
                        }
                    }
                });
            }
        }
        let guide = fitted.as_ref().and_then(|f| f.as_ref().ok());
        // A margin that folds over itself seen from the root's side (a jagged gum line on a
        // steep wall) loses the triangles hanging at the folds first, while rounds remain.
        if let Some(m) = margin
            && trims < max_trims
        {
            let folds = match guide {
                Some((t, f)) => {
                    root::tangles_along(&base, &loops[m], f.origin, f.apical(), f.root_length(t))
                }
                None => root::tangles(&base, &loops[m], root_length)?,
            };
            let at: HashSet<u32> = folds.into_iter().map(|k| loops[m][k]).collect();
            if !at.is_empty() {
                let cut: HashSet<usize> = (0..crown.triangles.len())
                    .filter(|&t| crown.triangles[t].iter().any(|v| at.contains(v)))
                    .collect();
                if repairs.triangles_cut + repairs.margin_trimmed + cut.len() <= budget {
                    repairs.margin_trimmed += cut.len();
                    crown = remove(crown, &cut, limits, repairs)?;
                    trims += 1;
                    continue;
                }
            }
        }
        let gaps: &[f32] = if margin.is_some() {
            &root::GAPS_MM
        } else {
            &[0.0]
        };
        let mut fewest: Option<(TriMesh, Vec<(usize, usize)>)> = None;
        // With a template, each gap is tried with the body's star-shaped band first (the
        // template's sections and roots), then without it.
        let bodies: &[bool] = if guide.is_some() {
            &[true, false]
        } else {
            &[false]
        };
        let attempts = gaps
            .iter()
            .flat_map(|&g| bodies.iter().map(move |&b| (g, b)));
        for (gap, star_body) in attempts {
            let mut mesh = base.clone();
            let (cervical, root, apical) = match (margin, guide) {
                (Some(m), Some((t, f))) => {
                    let r = sweep::close_with_template(&mut mesh, &loops[m], gap, t, f, star_body)?;
                    let (tilt_deg, shortened_mm) = match choice {
                        RootChoice::Template(g) => (
                            g.tilt.length().to_degrees(),
                            g.shorten * t.anatomy.root_length,
                        ),
                        RootChoice::Cone => (0.0, 0.0),
                    };
                    let report = RootReport {
                        kind: "template",
                        roots: r.roots,
                        length_mm: r.length_mm,
                        axis_deg: r.axis_deg,
                        fit_rms_mm: Some(f.rms_mm),
                        tilt_deg,
                        shortened_mm,
                        fallback: None,
                    };
                    (Some(r.cervical), Some(report), Some(f.apical()))
                }
                (Some(m), None) => {
                    let (c, a) = root::close_with_root(&mut mesh, &loops[m], root_length, gap)?;
                    let report = RootReport {
                        kind: "cone",
                        roots: 1,
                        length_mm: root_length,
                        axis_deg: root::LEAN_RAD.to_degrees() as f32,
                        fit_rms_mm: None,
                        tilt_deg: 0.0,
                        shortened_mm: 0.0,
                        fallback: fitted
                            .as_ref()
                            .and_then(|f| f.as_ref().err())
                            .filter(|e| **e != NoTemplate::NotAsked)
                            .map(|e| e.to_string()),
                    };
                    (Some(c), Some(report), Some(a))
                }
                _ => (None, None, None),
            };
            if mesh.signed_volume() < 0.0 {
                for t in &mut mesh.triangles {
                    t.swap(1, 2);
                }
                repairs.turned_outward = true;
            } else {
                repairs.turned_outward = false;
            }
            mesh.validate().map_err(|e| explain(&mesh, e))?;
            let pairs = mesh.self_intersections(MAX_PAIRS);
            if pairs.is_empty() {
                repairs.holes_closed_mm.extend(holes);
                repairs.root_generated_margin_mm = margin.map(|m| lengths[m]);
                repairs.root = root;
                let crown_rotation = match (choice, guide) {
                    (RootChoice::Template(g), Some((_, f))) => Some(
                        (glam::Quat::from_scaled_axis(g.tilt).inverse() * f.rotation).normalize(),
                    ),
                    _ => None,
                };
                return Ok(Closed {
                    mesh: mesh.without_unused_vertices(),
                    cervical,
                    apical,
                    crown_rotation,
                });
            }
            if fewest.as_ref().is_none_or(|(_, p)| pairs.len() < p.len()) {
                fewest = Some((mesh, pairs));
            }
        }
        let (mesh, pairs) = fewest.expect("at least one attempt");
        let cut = patches_to_cut(&crown, &mesh, &pairs);
        if round == MAX_CUTS
            || cut.is_empty()
            || repairs.triangles_cut + repairs.margin_trimmed + cut.len() > budget
        {
            let (a, b) = pairs[0];
            return Err(explain(&mesh, MeshError::SelfIntersecting { a, b }));
        }
        repairs.self_intersections_cut += 1;
        repairs.triangles_cut += cut.len();
        crown = remove(crown, &cut, limits, repairs)?;
        round += 1;
    }
}

/// `crown` without the triangles `cut`, its debris dropped and bow-ties split again.
fn remove(
    crown: TriMesh,
    cut: &HashSet<usize>,
    limits: &RepairLimits,
    repairs: &mut Repairs,
) -> Result<TriMesh, ImportError> {
    repairs.changed_areas.extend(areas(&crown, cut));
    let triangles: Vec<[u32; 3]> = crown
        .triangles
        .iter()
        .enumerate()
        .filter(|(i, _)| !cut.contains(i))
        .map(|(_, t)| *t)
        .collect();
    let mut vertices = crown.vertices;
    let mut triangles = repair::keep_main_piece(&vertices, triangles, limits, repairs)?;
    let split = super::mend::split_bowties(&mut vertices, &mut triangles);
    repairs.split_vertices += split.len();
    repairs.changed_areas.extend(split);
    Ok(TriMesh::new(vertices, triangles))
}

/// Crown triangles to remove for the crossing `pairs` of `closed` (whose first triangles are
/// `crown`'s): those with a vertex within [`CUT_RADIUS_EDGES`] mean edges (at least
/// [`CUT_RADIUS_MM`]) of a crossing crown triangle, or of a crown vertex that a crossing
/// generated triangle hangs from.
fn patches_to_cut(crown: &TriMesh, closed: &TriMesh, pairs: &[(usize, usize)]) -> HashSet<usize> {
    let own = crown.triangles.len();
    let mut seeds: Vec<Vec3> = Vec::new();
    for &(a, b) in pairs {
        for t in [a, b] {
            if t < own {
                let [p, q, r] = crown.triangle(t);
                seeds.push((p + q + r) / 3.0);
            } else {
                seeds.extend(
                    closed.triangles[t]
                        .iter()
                        .filter(|&&v| (v as usize) < crown.vertices.len())
                        .map(|&v| crown.vertices[v as usize]),
                );
            }
        }
    }
    near_points(crown, &seeds, CUT_RADIUS_EDGES, CUT_RADIUS_MM)
}

/// Crown triangles with a vertex within `edges` mean edge lengths (at least `min_mm`) of one of
/// `points`.
fn near_points(crown: &TriMesh, points: &[Vec3], edges: f32, min_mm: f32) -> HashSet<usize> {
    let radius = (crown.mean_edge_length() * edges).max(min_mm);
    let key = |p: Vec3| (p / radius).floor().as_ivec3();
    let mut grid: HashMap<IVec3, Vec<Vec3>> = HashMap::new();
    for &s in points {
        grid.entry(key(s)).or_default().push(s);
    }
    let near = |p: Vec3| {
        let k = key(p);
        (-1..=1).any(|dx| {
            (-1..=1).any(|dy| {
                (-1..=1).any(|dz| {
                    grid.get(&k.saturating_add(IVec3::new(dx, dy, dz)))
                        .is_some_and(|l| l.iter().any(|s| s.distance(p) <= radius))
                })
            })
        })
    };
    let close_vertex: Vec<bool> = crown.vertices.iter().map(|&p| near(p)).collect();
    (0..crown.triangles.len())
        .filter(|&t| crown.triangles[t].iter().any(|&v| close_vertex[v as usize]))
        .collect()
}

/// The places a cut removed: each connected group of cut triangles as the centre of its
/// vertices and the distance to the farthest one.
fn areas(crown: &TriMesh, cut: &HashSet<usize>) -> Vec<[f32; 4]> {
    let mut list: Vec<usize> = cut.iter().copied().collect();
    list.sort_unstable();
    let mut by_vertex: HashMap<u32, Vec<usize>> = HashMap::new();
    for &t in &list {
        for v in crown.triangles[t] {
            by_vertex.entry(v).or_default().push(t);
        }
    }
    let mut seen: HashSet<usize> = HashSet::new();
    let mut out = Vec::new();
    for &start in &list {
        if !seen.insert(start) {
            continue;
        }
        let mut group = vec![start];
        let mut k = 0;
        while k < group.len() {
            for v in crown.triangles[group[k]] {
                for &t in &by_vertex[&v] {
                    if seen.insert(t) {
                        group.push(t);
                    }
                }
            }
            k += 1;
        }
        let points: Vec<Vec3> = group.iter().flat_map(|&t| crown.triangle(t)).collect();
        let centre = points.iter().copied().sum::<Vec3>() / points.len() as f32;
        let radius = points
            .iter()
            .map(|p| p.distance(centre))
            .fold(0.0, f32::max);
        out.push([centre.x, centre.y, centre.z, radius]);
    }
    out
}

/// A mesh error with the place it is at.
pub(super) fn explain(mesh: &TriMesh, e: MeshError) -> ImportError {
    let centre = |t: usize| {
        let [a, b, c] = mesh.triangle(t);
        (a + b + c) / 3.0
    };
    match e {
        MeshError::SelfIntersecting { a, b } => ImportError::SelfIntersecting {
            a,
            b,
            at: Near(centre(a)),
        },
        MeshError::Degenerate { triangle, .. } => ImportError::Degenerate(Near(centre(triangle))),
        MeshError::Inverted { volume } => ImportError::Flat { volume },
        other => ImportError::NotSolid(other),
    }
}
