//! A map's history as a 4-D tree (`map::MapHistory`): the map it gives after each step is the map that
//! was integrated up to that step; its static map and what moved are the voxel-by-voxel classification of
//! the steps' maps; and on a room with a person walking through it, the person's trail is separated from
//! the walls and furniture.

use ktree::map::{state_labels, HistoryRecorder, MapHistory, OccupancyMap, FREE, OCCUPIED};
use ktree::KTree;
use ktree_verify::scenes::{Aabb, WalkingPerson};
use proptest::prelude::*;

/// Integrates the scans, recording each step; returns the map, the history and every step's labels.
fn integrate(
    resolution: f64,
    scans: &[(Vec<[f32; 3]>, [f32; 3])],
) -> (OccupancyMap<3>, MapHistory, Vec<KTree<3, u8>>) {
    let mut map = OccupancyMap::<3>::new(resolution).unwrap();
    let mut recorder = HistoryRecorder::new(*map.grid());
    let mut steps = Vec::new();
    for (points, origin) in scans {
        map.insert(points, *origin, None).unwrap();
        recorder.record(&map).unwrap();
        steps.push(state_labels(&map));
    }
    (map, recorder.finish(), steps)
}

/// Every voxel of the keys' box, classified from the steps' labels: (static, moved).
fn classify(steps: &[KTree<3, u8>], lo: u32, hi: u32) -> (Vec<[u32; 3]>, Vec<[u32; 3]>) {
    let (mut still, mut moved) = (Vec::new(), Vec::new());
    for x in lo..hi {
        for y in lo..hi {
            for z in lo..hi {
                let p = [x, y, z];
                let seen: Vec<Option<u8>> = steps.iter().map(|s| s.value_at(p)).collect();
                let occupied = seen.contains(&Some(OCCUPIED));
                let free = seen.contains(&Some(FREE));
                if occupied && free {
                    moved.push(p);
                } else if occupied {
                    still.push(p);
                }
            }
        }
    }
    (still, moved)
}

proptest! {
    #![proptest_config(ktree_verify::config(24))]
    /// Random scans of a small region at 1 m: each step's map is given back, and the static map and what
    /// moved are the classification of every voxel by the states it had.
    #[test]
    fn a_history_gives_each_steps_map_and_separates_what_moved(
        scans in prop::collection::vec(
            (prop::collection::vec(prop::array::uniform3(-3.9f32..3.9), 1..12), prop::array::uniform3(-1.9f32..1.9)),
            1..7,
        )
    ) {
        let (_, history, steps) = integrate(1.0, &scans);
        prop_assert_eq!(history.steps() as usize, steps.len());
        for (t, labels) in steps.iter().enumerate() {
            prop_assert_eq!(&history.at(t as u32).unwrap(), labels);
        }
        // Every point and origin lies in keys 32764..32772.
        let (still, moved) = classify(&steps, 32764, 32772);
        let (s, m) = (history.static_map(), history.moved());
        prop_assert_eq!(s.voxel_count(), still.len() as u128);
        prop_assert!(still.iter().all(|&p| s.contains(p)));
        prop_assert_eq!(m.voxel_count(), moved.len() as u128);
        prop_assert!(moved.iter().all(|&p| m.contains(p)));
        // A history read back from its tree alone is the same.
        let again = MapHistory::from_tree(*history.grid(), history.tree().clone(), Some(history.steps())).unwrap();
        prop_assert_eq!(&again, &history);
    }
}

proptest! {
    #![proptest_config(ktree_verify::config(12))]
    /// Over more steps than the recorder builds at a time (and a number that may end in the middle of
    /// one of its chunks), the history it builds step by step is the one built from every step's states
    /// at once, node for node; scans that see one region again and again (a moving point in front of a
    /// wall) leave most cells alike across steps, so whole cells of time are settled above the chunks.
    #[test]
    fn a_history_recorded_step_by_step_is_the_one_built_at_once(
        scans in prop::collection::vec(
            (prop::collection::vec(prop::array::uniform3(-3.9f32..3.9), 0..4), prop::array::uniform3(-1.9f32..1.9)),
            1..40,
        ),
        wall in 1usize..4,
    ) {
        let scans: Vec<_> = scans
            .into_iter()
            .enumerate()
            .map(|(t, (mut points, origin))| {
                if t % wall == 0 {
                    points.extend((0..6).map(|i| [3.5f32, i as f32 - 2.5, 0.5]));
                }
                (points, if t % 3 == 0 { [0.5; 3] } else { origin })
            })
            .collect();
        let (_, history, steps) = integrate(1.0, &scans);
        let at_once = MapHistory::from_steps(*history.grid(), &steps).unwrap();
        prop_assert_eq!(&history, &at_once);
        for (t, labels) in steps.iter().enumerate() {
            prop_assert_eq!(&history.at(t as u32).unwrap(), labels);
        }
    }
}

#[test]
fn a_history_built_at_once_refuses_other_states() {
    let grid = ktree::map::MapGrid::new(0.1).unwrap();
    let (_, history, mut steps) = integrate(1.0, &vec![(vec![[2.5, 0.5, 0.5]], [0.5; 3]); 3]);
    assert_eq!(
        MapHistory::from_steps(grid, &steps).unwrap().tree(),
        history.tree()
    );
    steps[1] = steps[1].map_values(|v| Some(v + 1)).unwrap();
    assert!(MapHistory::from_steps(grid, &steps)
        .unwrap_err()
        .contains("step 1"));
    let small = KTree::<3, u8>::from_dense_values(1, &[Some(FREE); 8]).unwrap();
    assert!(MapHistory::from_steps(grid, &[small])
        .unwrap_err()
        .contains("level"));
}

#[test]
fn a_history_is_refused_with_other_values_levels_or_too_few_steps() {
    let grid = ktree::map::MapGrid::new(0.1).unwrap();
    let small = KTree::<4, u8>::from_dense_values(1, &[Some(FREE); 16]).unwrap();
    assert!(MapHistory::from_tree(grid, small, None)
        .unwrap_err()
        .contains("level"));
    let (_, history, _) = integrate(1.0, &vec![(vec![[2.5, 0.5, 0.5]], [0.5; 3]); 3]);
    let tree = history.tree().clone();
    let e = MapHistory::from_tree(grid, tree.map_values(|v| Some(v + 5)).unwrap(), None);
    assert!(e.unwrap_err().contains("not 6"));
    assert!(MapHistory::from_tree(grid, tree.clone(), Some(0)).is_err());
    assert!(history.at(history.steps()).is_err());
}

/// The keys of the voxels a box touches, above the floor's row of voxels.
fn voxels_of(map: &OccupancyMap<3>, b: &Aabb) -> Vec<[u32; 3]> {
    let g = map.grid();
    let range = |a: usize| {
        let lo = g.key(b.lo[a]).unwrap();
        let hi = g.key(b.hi[a]).unwrap();
        lo..=hi
    };
    let floor = g.key(0.1).unwrap();
    let mut out = Vec::new();
    for x in range(0) {
        for y in range(1) {
            for z in range(2) {
                if z >= floor {
                    out.push([x, y, z]);
                }
            }
        }
    }
    out
}

/// The full voxels of a tree.
fn voxels(tree: &KTree<3>) -> Vec<[u32; 3]> {
    let mut out = Vec::new();
    for (cell, state) in tree.leaves() {
        if state != ktree::NodeState::Full {
            continue;
        }
        let (o, side) = (cell.origin(), cell.side() as u32);
        for x in 0..side {
            for y in 0..side {
                for z in 0..side {
                    out.push([o[0] + x, o[1] + y, o[2] + z]);
                }
            }
        }
    }
    out
}

#[test]
fn a_person_walking_through_a_room_is_separated_from_the_room() {
    let scene = WalkingPerson::new(24);
    let scans: Vec<_> = (0..scene.steps)
        .map(|t| {
            let s = scene.scan(t, 360, 64);
            (s.points, s.origin)
        })
        .collect();
    let (map, history, steps) = integrate(0.1, &scans);
    for (t, labels) in steps.iter().enumerate() {
        assert_eq!(&history.at(t as u32).unwrap(), labels, "step {t}");
    }
    // Recorded step by step in chunks of steps, the same tree as built from every step at once.
    assert_eq!(
        history,
        MapHistory::from_steps(*history.grid(), &steps).unwrap()
    );
    let (still, moved) = (history.static_map(), history.moved());
    // The person's voxels over the whole walk (grown by a voxel: its surface's hits fall on either side).
    let mut walked = std::collections::HashSet::new();
    for t in 0..scene.steps {
        let mut b = scene.person(t);
        b.lo = b.lo.map(|c| c - 0.1);
        b.hi = b.hi.map(|c| c + 0.1);
        walked.extend(voxels_of(&map, &b));
    }
    let in_walk = |tree: &KTree<3>| voxels(tree).iter().filter(|p| walked.contains(*p)).count();
    let occupied = map.occupied();
    eprintln!(
        "occupied at the end {}, static {} ({} in the walk), moved {} ({} in the walk); history {} nodes, final map {} nodes, {} steps",
        occupied.voxel_count(),
        still.voxel_count(),
        in_walk(&still),
        moved.voxel_count(),
        in_walk(&moved),
        history.tree().node_count(),
        steps.last().unwrap().node_count(),
        scene.steps
    );
    // Nothing the person occupied is in the static map; everything that moved was the person.
    assert_eq!(in_walk(&still), 0);
    // Nearly everything that moved was the person. The rest (18 voxels here) is where rays graze a
    // surface: a voxel of the floor's row (or of the cupboard's edge) crossed by a ray on its way to a
    // farther point is observed free, and occupied when a ray ends in it — OctoMap's own behaviour.
    let elsewhere = moved.voxel_count() - in_walk(&moved) as u128;
    assert!(
        elsewhere * 20 < moved.voxel_count(),
        "{elsewhere} moved outside the walk"
    );
    assert!(moved.voxel_count() > 100);
    // The room is kept: the voxels occupied at the end outside the walk are static but for the grazed
    // ones (7 here, of 8 000).
    let room: Vec<_> = voxels(&occupied)
        .into_iter()
        .filter(|p| !walked.contains(p))
        .collect();
    let lost = room.iter().filter(|p| !still.contains(**p)).count();
    assert!(
        lost * 100 < room.len(),
        "{lost} of {} room voxels left out",
        room.len()
    );
    // The history records the room once and the changes: far below a tree of every step's map.
    assert!(history.tree().node_count() < 4 * steps.last().unwrap().node_count());
    // And the recorder never held every step: a few maps' states and each step's coarse states.
    let mut recorder = HistoryRecorder::new(*map.grid());
    let mut replay = OccupancyMap::<3>::new(0.1).unwrap();
    let (mut held, every_step) = (0usize, steps.iter().map(KTree::heap_bytes).sum::<usize>());
    for (points, origin) in &scans {
        replay.insert(points, *origin, None).unwrap();
        recorder.record(&replay).unwrap();
        held = held.max(recorder.heap_bytes());
    }
    eprintln!("the recorder held at most {held} bytes, every step's states {every_step}");
    // (About 11 maps' worth over these 24 steps: the 9 steps of a chunk and the coarse states.)
    assert!(held < every_step, "{held} of {every_step} bytes");
    // The static occupancy map: what moved made free.
    let cleared = map.cleared(&moved).unwrap();
    assert_eq!(
        cleared.occupied(),
        ktree::ops::difference(&occupied, &moved).unwrap()
    );
}
