//! Bradshaw's `.sph` text format, so trees can be exchanged with his sphere-tree toolkit.
//!
//! First line: `levels branching`. Then one line per slot of the full tree, in index order:
//! `x y z r`, optionally followed by more numbers (Bradshaw writes an error value), which are
//! ignored. A slot is unused when its radius is not positive; orthosim writes unused slots as
//! `0 0 0 -1`. Leaf triangle lists are not stored: recompute them with
//! [`SphereTree::assign_triangles`].

use std::fmt::Write as _;

use glam::Vec3;
use thiserror::Error;

use super::tree::{SphereTree, triangles_touching};
use crate::geometry::{Sphere, TriMesh};

/// A `.sph` text that cannot be read.
#[derive(Clone, Debug, Error, PartialEq, Eq)]
#[error("line {line}: {message}")]
pub struct SphError {
    /// 1-based line.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

/// Largest tree accepted when reading (slots), to refuse absurd headers before allocating.
const MAX_SLOTS: usize = 50_000_000;

impl SphereTree {
    /// The tree as `.sph` text.
    pub fn to_sph(&self) -> String {
        let mut out = format!("{} {}\n", self.levels, self.branching);
        for node in &self.nodes {
            match node {
                Some(s) => {
                    let _ = writeln!(
                        out,
                        "{} {} {} {}",
                        s.centre.x, s.centre.y, s.centre.z, s.radius
                    );
                }
                None => out.push_str("0 0 0 -1\n"),
            }
        }
        out
    }

    /// Reads `.sph` text.
    pub fn from_sph(text: &str) -> Result<Self, SphError> {
        let err = |line: usize, message: String| SphError { line, message };
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty());
        let (header_no, header) = lines.next().ok_or_else(|| err(1, "empty file".into()))?;
        let nums: Vec<&str> = header.split_whitespace().collect();
        let parse_u32 = |s: &str, what: &str| {
            s.parse::<u32>().map_err(|_| {
                err(
                    header_no + 1,
                    format!("{what} must be a whole number, got '{s}'"),
                )
            })
        };
        if nums.len() < 2 {
            return Err(err(header_no + 1, "expected `levels branching`".into()));
        }
        let levels = parse_u32(nums[0], "levels")?;
        let branching = parse_u32(nums[1], "branching")?;
        if levels == 0 || branching < 2 {
            return Err(err(
                header_no + 1,
                format!("need levels ≥ 1 and branching ≥ 2, got {levels} {branching}"),
            ));
        }
        let slots = (0..levels)
            .try_fold(0usize, |acc, l| {
                (branching as usize)
                    .checked_pow(l)
                    .and_then(|p| acc.checked_add(p))
            })
            .filter(|&n| n <= MAX_SLOTS)
            .ok_or_else(|| {
                err(
                    header_no + 1,
                    format!("a tree of {levels} levels and branching {branching} is too large"),
                )
            })?;
        let mut tree = SphereTree::empty(branching, levels);
        for slot in 0..slots {
            let (no, line) = lines.next().ok_or_else(|| {
                err(
                    text.lines().count() + 1,
                    format!("expected {slots} spheres, found {slot}"),
                )
            })?;
            let v: Vec<f32> = line
                .split_whitespace()
                .take(4)
                .map(|s| {
                    s.parse::<f32>()
                        .map_err(|_| err(no + 1, format!("'{s}' is not a number")))
                })
                .collect::<Result<_, _>>()?;
            if v.len() < 4 {
                return Err(err(no + 1, "expected `x y z r`".into()));
            }
            if v.iter().any(|x| !x.is_finite()) {
                return Err(err(no + 1, "numbers must be finite".into()));
            }
            if v[3] > 0.0 {
                tree.nodes[slot] = Some(Sphere::new(Vec3::new(v[0], v[1], v[2]), v[3]));
            }
        }
        if let Some((no, _)) = lines.next() {
            return Err(err(
                no + 1,
                format!("more than the {slots} spheres the header announces"),
            ));
        }
        Ok(tree)
    }

    /// Fills each leaf's triangle list with the triangles of `mesh` that touch its sphere.
    pub fn assign_triangles(&mut self, mesh: &TriMesh) {
        let leaves: Vec<usize> = self.leaves().collect();
        for list in &mut self.triangles {
            list.clear();
        }
        for n in leaves {
            let Some(s) = self.nodes[n] else { continue };
            self.triangles[n] = triangles_touching(mesh, &s);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_keeps_every_sphere() {
        let mut t = SphereTree::empty(2, 3);
        t.nodes[0] = Some(Sphere::new(Vec3::new(0.5, -1.25, 3.0), 4.5));
        t.nodes[1] = Some(Sphere::new(Vec3::new(0.1, 0.2, 0.3), 1.0 / 3.0));
        t.nodes[4] = Some(Sphere::new(Vec3::new(-7.0, 0.0, 1e-7), 0.25));
        let back = SphereTree::from_sph(&t.to_sph()).unwrap();
        assert_eq!(back.nodes, t.nodes);
    }

    #[test]
    fn bradshaw_files_with_error_columns_read() {
        let text = "2 2\n0 0 0 2 0.01\n-1 0 0 1 0.0\n1 0 0 1 0.0\n";
        let t = SphereTree::from_sph(text).unwrap();
        assert_eq!(t.leaves().count(), 2);
    }

    #[test]
    fn malformed_files_name_the_line() {
        for (text, line) in [
            ("", 1),
            ("2\n", 1),
            ("x 8\n", 1),
            ("2 2\n0 0 0 1\n0 0 nan 1\n0 0 0 1\n", 3),
            ("2 2\n0 0 0 1\n0 0 0\n0 0 0 1\n", 3),
            ("2 2\n0 0 0 1\n", 3),
            ("2 2\n0 0 0 1\n0 0 0 1\n0 0 0 1\n0 0 0 1\n", 5),
            ("99 99\n", 1),
        ] {
            let e = SphereTree::from_sph(text).unwrap_err();
            assert_eq!(e.line, line, "{text:?}: {e}");
        }
    }
}
