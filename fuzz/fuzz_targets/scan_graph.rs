//! The scan graph reader (OctoMap's `.graph`) on arbitrary bytes, and the scan log reader on the same bytes:
//! they never panic; an accepted graph is exactly its nodes' bytes and whole edges, and its scans are placed.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if let Ok(nodes) = ktree::io::read_scan_graph(data, Path::new("fuzz")) {
        ktree_fuzz::check_scan_nodes(&nodes);
        // The counts, the poses (64 bytes) and ids; then the edge count and whole edges of 80 bytes.
        let node_bytes: usize = nodes.iter().map(|n| 4 + 28 * n.points.len() + 64 + 4).sum();
        let edge_bytes = data.len() - 4 - node_bytes - 4;
        assert_eq!(
            edge_bytes % 80,
            0,
            "an accepted graph ends in a part of an edge"
        );
    }
    if let Ok(nodes) = ktree::io::read_scan_log(data, Path::new("fuzz")) {
        ktree_fuzz::check_scan_nodes(&nodes);
    }
});
