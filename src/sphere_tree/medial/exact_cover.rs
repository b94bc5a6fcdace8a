//! Phase 6 of the medial builder: every piece of the surface given to a sphere that holds it
//! exactly, splitting pieces no single sphere holds.

use glam::Vec3;

use super::{grids::SphereGrid, padded, pieces::Pieces, reach};
use crate::{geometry::Sphere, sphere_tree::coverage::split4};

/// Gives every piece of the surface to a sphere that holds it (splitting pieces that no single
/// sphere holds, and growing the sphere that needs the least growth for a piece still unheld at the
/// split limit), then shrinks every sphere to its pieces. A piece whose hinted sphere (`hint`, or
/// `u32::MAX` for none) holds its corners goes to it without a search; any other piece and its
/// parts look first among the spheres of its lattice points (`lattice_owner`, `per_piece` per
/// piece; `u32::MAX` for a dropped sphere). Returns the leaves that hold pieces and the corners of
/// their pieces.
pub(super) fn cover_exact(
    mut spheres: Vec<Sphere>,
    pieces: &Pieces,
    hint: &[u32],
    (lattice_owner, per_piece): (&[u32], usize),
    cell: f32,
) -> (Vec<Sphere>, Vec<Vec<Vec3>>) {
    const SPLITS: u32 = 5;
    let grid = SphereGrid::new(&spheres, cell);
    let mut owned: Vec<Vec<Vec3>> = vec![Vec::new(); spheres.len()];
    let mut stack = Vec::new();
    // A numbered corner is listed once per sphere as far as neighbouring pieces show it.
    let mut mark = vec![u32::MAX; pieces.corner_at.len()];
    for (i, ((piece, &h), ids)) in pieces
        .corners
        .iter()
        .zip(hint)
        .zip(&pieces.corner_id)
        .enumerate()
    {
        if let Some(s) = spheres.get(h as usize)
            && piece.iter().all(|&q| s.contains(q))
        {
            for (&q, &id) in piece.iter().zip(ids) {
                if mark[id as usize] != h {
                    mark[id as usize] = h;
                    owned[h as usize].push(q);
                }
            }
            continue;
        }
        let lattice = &lattice_owner[i * per_piece..(i + 1) * per_piece];
        let orphaned = lattice.contains(&u32::MAX);
        // The distinct spheres of the piece's lattice points.
        let mut owners = Vec::with_capacity(4);
        for &k in lattice {
            if k != u32::MAX && !owners.contains(&k) {
                owners.push(k);
            }
        }
        stack.push((*piece, 0u32));
        while let Some((p, depth)) = stack.pop() {
            let most_room = |among: &mut dyn Iterator<Item = u32>| {
                among
                    .filter(|&k| p.iter().all(|&q| spheres[k as usize].contains(q)))
                    .map(|k| {
                        (
                            k,
                            reach(&p, spheres[k as usize].centre) / spheres[k as usize].radius,
                        )
                    })
                    .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
            };
            // The spheres of the piece's lattice points; every sphere near it only where one of
            // those was dropped, or before the last resort of growing one.
            let near = grid.near((p[0] + p[1] + p[2]) / 3.0);
            let best = most_room(&mut owners.iter().copied()).or_else(|| {
                (orphaned || depth >= SPLITS)
                    .then(|| most_room(&mut near.iter().copied()))
                    .flatten()
            });
            if let Some((k, _)) = best {
                owned[k as usize].extend_from_slice(&p);
                continue;
            }
            if depth < SPLITS {
                stack.extend(split4(p).map(|x| (x, depth + 1)));
                continue;
            }
            let growth = |k: usize| reach(&p, spheres[k].centre) - spheres[k].radius;
            let k = near
                .iter()
                .map(|&k| k as usize)
                .chain(
                    (near.is_empty())
                        .then_some(0..spheres.len())
                        .into_iter()
                        .flatten(),
                )
                .min_by(|&a, &b| growth(a).total_cmp(&growth(b)).then(a.cmp(&b)))
                .expect("at least one sphere");
            spheres[k].radius = padded(reach(&p, spheres[k].centre)).max(spheres[k].radius);
            owned[k].extend_from_slice(&p);
        }
    }
    for (s, points) in spheres.iter_mut().zip(&owned) {
        let r = points
            .iter()
            .map(|p| p.distance(s.centre))
            .fold(0.0f32, f32::max);
        s.radius = padded(r).min(s.radius);
    }
    spheres
        .into_iter()
        .zip(owned)
        .filter(|(_, c)| !c.is_empty())
        .unzip()
}
