//! OctoMap's scan graph files (`.graph`), as `ScanGraph::writeBinary` writes them: scans in their sensor's
//! frame, each with its pose, and edges between them. Little-endian, as OctoMap writes on the machines it
//! runs on:
//!
//! ```text
//! u32 n                                   the number of nodes, then n nodes:
//!   u32 m                                 the number of points, then m points:
//!     i32 3, f64 x, f64 y, f64 z          a point in the sensor's frame
//!   i32 3, f64 x, f64 y, f64 z            the pose's translation
//!   i32 4, f64 w, f64 x, f64 y, f64 z     the pose's rotation (a quaternion)
//!   u32 id
//! u32 e                                   the number of edges, then e edges:
//!   u32 first id, u32 second id, a pose (as above), f64 weight
//! ```
//!
//! OctoMap keeps every number as an `f32` (the `f64`s are rounded as they are read) and so does ktree.

use std::collections::HashSet;
use std::path::Path;

use super::pose::Pose;
use super::Scan;
use crate::io::geometry_file::{Fault, GeometryFileError};

/// The bytes of a point: its length (3) and three `f64`.
const POINT_BYTES: usize = 4 + 3 * 8;
/// The bytes of a pose: a vector of 3 and a quaternion of 4.
const POSE_BYTES: usize = POINT_BYTES + 4 + 4 * 8;
/// The fewest bytes of a node: no points, its pose and its id.
const NODE_MIN_BYTES: usize = 4 + POSE_BYTES + 4;
/// The bytes of an edge: two ids, a pose and a weight.
const EDGE_BYTES: usize = 4 + 4 + POSE_BYTES + 8;

/// One scan of a scan graph: its points in the sensor's frame and the pose that places them in the world.
///
/// ```
/// use ktree::io::{Pose, ScanNode};
/// let node = ScanNode { id: 0, pose: Pose::from_xyz_rpy(1.0, 2.0, 0.5, 0.0, 0.0, 0.0), points: vec![[1.0, 0.0, 0.0]] };
/// let scan = node.to_scan();
/// assert_eq!(scan.points, [[2.0, 2.0, 0.5]]);
/// assert_eq!(scan.origin, [1.0, 2.0, 0.5]);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ScanNode {
    /// The node's id in its graph.
    pub id: u32,
    /// Where the sensor was: its frame's motion into the world.
    pub pose: Pose,
    /// The points, in the sensor's frame.
    pub points: Vec<[f32; 3]>,
}

impl ScanNode {
    /// The scan in world coordinates, as OctoMap's `OccupancyOcTreeBase::insertPointCloud(const ScanNode&)`
    /// computes it: every point moved by the pose, and the sensor at the pose's translation taken back by
    /// the inverse pose and forth again (`pose.transform(pose.inv().transform(pose.trans()))`, which differs
    /// from the translation by rounding, as OctoMap's does).
    pub fn to_scan(&self) -> Scan {
        let pose = self.pose;
        let sensor = pose.inverse().transform(pose.translation);
        Scan {
            points: self.points.iter().map(|&p| pose.transform(p)).collect(),
            origin: pose.transform(sensor),
        }
    }
}

/// Reads the bytes of a scan graph (`file` names it in errors): its nodes, in the file's order. The edges
/// (constraints between nodes, which building a map does not use) are read and checked — they must join
/// nodes of the graph — and not kept.
///
/// ```
/// use ktree::io::read_scan_graph;
/// let mut bytes = 1u32.to_le_bytes().to_vec(); // one node
/// bytes.extend(1u32.to_le_bytes()); // of one point
/// for v in [[3.0, 1.0, 2.0, 3.0].as_slice(), &[3.0, 0.0, 0.0, 0.5], &[4.0, 1.0, 0.0, 0.0, 0.0]] {
///     bytes.extend((v[0] as i32).to_le_bytes()); // the length, then the numbers
///     v[1..].iter().for_each(|x: &f64| bytes.extend(x.to_le_bytes()));
/// }
/// bytes.extend(7u32.to_le_bytes()); // its id
/// bytes.extend(0u32.to_le_bytes()); // no edges
/// let nodes = read_scan_graph(&bytes, "one.graph".as_ref()).unwrap();
/// assert_eq!((nodes[0].id, nodes[0].points.clone()), (7, vec![[1.0, 2.0, 3.0]]));
/// assert_eq!(nodes[0].to_scan().points, [[1.0, 2.0, 3.5]]);
/// // Cut short: one node needs at least 72 bytes, 16 are left after its count.
/// let e = read_scan_graph(&bytes[..20], "one.graph".as_ref()).unwrap_err();
/// assert_eq!(e.offset(), Some(0));
/// ```
///
/// # Errors
/// [`GeometryFileErrorKind::Malformed`](crate::io::GeometryFileErrorKind::Malformed) naming the byte offset:
/// bytes missing (every count is checked against the bytes left before anything is allocated), a vector
/// or quaternion whose stored length is not 3 or 4, a number that is not finite as an `f32`, an edge naming
/// a node the graph does not have, bytes after the last edge.
pub fn read_scan_graph(bytes: &[u8], file: &Path) -> Result<Vec<ScanNode>, GeometryFileError> {
    parse_graph(bytes).map_err(|fault| fault.in_file(file))
}

fn parse_graph(bytes: &[u8]) -> Result<Vec<ScanNode>, Fault> {
    let mut r = Reader { bytes, at: 0 };
    let count = r.count("nodes", NODE_MIN_BYTES)?;
    let mut nodes = Vec::with_capacity(count);
    for _ in 0..count {
        let points_count = r.count("points", POINT_BYTES)?;
        let mut points = Vec::with_capacity(points_count);
        for _ in 0..points_count {
            points.push(r.vector::<3>("a point")?);
        }
        let pose = r.pose()?;
        let id = r.u32("a node's id")?;
        nodes.push(ScanNode { id, pose, points });
    }
    let edges = r.count("edges", EDGE_BYTES)?;
    let ids: HashSet<u32> = nodes.iter().map(|n| n.id).collect();
    for _ in 0..edges {
        let at = r.at;
        for _ in 0..2 {
            let id = r.u32("an edge's node")?;
            if !ids.contains(&id) {
                return Err(Fault::byte(
                    at,
                    format!("an edge joins node {id}, which the graph does not have"),
                ));
            }
        }
        r.pose()?;
        r.finite_f64("an edge's weight")?;
    }
    if r.at != bytes.len() {
        return Err(Fault::byte(
            r.at,
            format!("{} bytes after the last edge", bytes.len() - r.at),
        ));
    }
    Ok(nodes)
}

/// A cursor over the bytes, every read checked.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self, what: &str) -> Result<[u8; N], Fault> {
        let Some(b) = self.bytes.get(self.at..self.at + N) else {
            return Err(Fault::byte(
                self.at,
                format!(
                    "the file ends in {what} ({N} bytes needed, {} left)",
                    self.bytes.len() - self.at
                ),
            ));
        };
        self.at += N;
        Ok(b.try_into().expect("N bytes"))
    }

    fn u32(&mut self, what: &str) -> Result<u32, Fault> {
        self.take::<4>(what).map(u32::from_le_bytes)
    }

    /// A count of items of at least `item_bytes` each, checked against the bytes left.
    fn count(&mut self, what: &str, item_bytes: usize) -> Result<usize, Fault> {
        let at = self.at;
        let count = self.u32(&format!("the number of {what}"))? as usize;
        let left = self.bytes.len() - self.at;
        if count > left / item_bytes {
            return Err(Fault::byte(
                at,
                format!(
                    "{count} {what} need at least {} bytes, {left} are left",
                    count as u128 * item_bytes as u128
                ),
            ));
        }
        Ok(count)
    }

    fn finite_f64(&mut self, what: &str) -> Result<f64, Fault> {
        let at = self.at;
        let v = f64::from_le_bytes(self.take::<8>(what)?);
        if !v.is_finite() {
            return Err(Fault::byte(at, format!("{what} is {v}")));
        }
        Ok(v)
    }

    /// OctoMap's vector or quaternion: its length `N`, then `N` numbers kept as `f32`.
    fn vector<const N: usize>(&mut self, what: &str) -> Result<[f32; N], Fault> {
        let at = self.at;
        let length = i32::from_le_bytes(self.take::<4>(what)?);
        if length != N as i32 {
            return Err(Fault::byte(
                at,
                format!("{what} has {N} numbers, but its stored length is {length}"),
            ));
        }
        let mut out = [0.0f32; N];
        for c in &mut out {
            let at = self.at;
            let v = f64::from_le_bytes(self.take::<8>(what)?) as f32;
            if !v.is_finite() {
                return Err(Fault::byte(
                    at,
                    format!("{what} has a number that is not finite as a float ({v})"),
                ));
            }
            *c = v;
        }
        Ok(out)
    }

    fn pose(&mut self) -> Result<Pose, Fault> {
        Ok(Pose {
            translation: self.vector::<3>("a pose's translation")?,
            rotation: self.vector::<4>("a pose's rotation")?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A graph of `nodes` (points and id, identity poses) and `edges`, as OctoMap writes it.
    fn graph(nodes: &[(Vec<[f64; 3]>, u32)], edges: &[(u32, u32)]) -> Vec<u8> {
        fn vector(out: &mut Vec<u8>, v: &[f64]) {
            out.extend((v.len() as i32).to_le_bytes());
            v.iter().for_each(|x| out.extend(x.to_le_bytes()));
        }
        fn pose(out: &mut Vec<u8>) {
            vector(out, &[0.0; 3]);
            vector(out, &[1.0, 0.0, 0.0, 0.0]);
        }
        let mut out = (nodes.len() as u32).to_le_bytes().to_vec();
        for (points, id) in nodes {
            out.extend((points.len() as u32).to_le_bytes());
            points.iter().for_each(|p| vector(&mut out, p));
            pose(&mut out);
            out.extend(id.to_le_bytes());
        }
        out.extend((edges.len() as u32).to_le_bytes());
        for (a, b) in edges {
            out.extend(a.to_le_bytes());
            out.extend(b.to_le_bytes());
            pose(&mut out);
            out.extend(1.0f64.to_le_bytes());
        }
        out
    }

    #[test]
    fn graphs_read_and_bad_ones_name_the_byte() {
        let nodes = vec![(vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]], 0), (vec![], 1)];
        let good = graph(&nodes, &[(0, 1)]);
        let read = parse_graph(&good).unwrap();
        assert_eq!(read.len(), 2);
        assert_eq!(read[0].points, [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
        assert_eq!((read[1].id, read[1].pose), (1, Pose::IDENTITY));
        // Every truncation is an error at or before the end, never a panic.
        for cut in 0..good.len() {
            let e = parse_graph(&good[..cut]).unwrap_err();
            let crate::io::Place::Byte(at) = e.place else {
                panic!("{e:?}")
            };
            assert!(at as usize <= cut, "{cut}: {e:?}");
        }
        // A count larger than the bytes could hold is refused where it stands.
        let mut huge = good.clone();
        huge[4..8].copy_from_slice(&u32::MAX.to_le_bytes());
        let e = parse_graph(&huge).unwrap_err();
        assert_eq!(e.place, crate::io::Place::Byte(4));
        assert!(e.message.contains("4294967295 points"), "{}", e.message);
        // A vector whose length is not 3.
        let mut bad = good.clone();
        bad[8] = 2;
        assert_eq!(
            parse_graph(&bad).unwrap_err().place,
            crate::io::Place::Byte(8)
        );
        // An edge to a node that is not there.
        let e = parse_graph(&graph(&nodes, &[(0, 5)])).unwrap_err();
        assert!(e.message.contains("node 5"), "{}", e.message);
        // Bytes after the edges.
        let mut longer = good.clone();
        longer.push(0);
        let e = parse_graph(&longer).unwrap_err();
        assert_eq!(e.place, crate::io::Place::Byte(good.len() as u64));
        // A NaN.
        let nan = graph(&[(vec![[f64::NAN, 0.0, 0.0]], 0)], &[]);
        assert_eq!(
            parse_graph(&nan).unwrap_err().place,
            crate::io::Place::Byte(12)
        );
    }
}
