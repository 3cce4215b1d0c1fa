//! Round trip: any ray file that reads is written and read back unchanged, and its stacked tree goes
//! through the `.ktree` format unchanged.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(rays) = ktree::io::read_rays(data, "fuzz") {
        ktree_fuzz::check_accepted_rays(&rays);
    }
});
