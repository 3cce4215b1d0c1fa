//! The navigable tree's memory: at most 2.1 bits a node (plus a small constant) on large trees, and the
//! rank index agrees with a plain count of the partial nodes on them.

use ktree::rays::ball_rays;
use ktree::stacking::paper::stack;
use ktree::NodeState;

#[test]
fn a_large_octree_takes_at_most_2_1_bits_a_node() {
    for level in [9, 10] {
        let u = 1i64 << level;
        let tree = stack(&ball_rays::<3>(level, [u, u, u], u).unwrap());
        let nodes = tree.node_count();
        let bytes = tree.heap_bytes() as u64;
        assert!(nodes > 1_000_000);
        assert!(
            bytes * 8 <= nodes * 21 / 10 + 8 * 4096,
            "L = {level}: {bytes} bytes for {nodes} nodes = {:.3} bits a node",
            bytes as f64 * 8.0 / nodes as f64
        );
        assert!(bytes >= tree.bytes_at_two_bits());
        // The children found through the rank index are the next level's nodes in order.
        for depth in 0..tree.depth_count() - 1 {
            let l = tree.level_states(depth);
            let mut partials = 0;
            for i in 0..l.len() {
                if l.get(i) == NodeState::Partial {
                    assert_eq!(tree.first_child(depth, i), partials << 3);
                    partials += 1;
                }
            }
            assert_eq!(tree.level_states(depth + 1).len(), partials << 3);
        }
    }
}
