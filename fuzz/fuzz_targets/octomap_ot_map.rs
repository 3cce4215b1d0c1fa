//! OctoMap `.ot` maps on arbitrary bytes, `OcTree` and `ColorOcTree` alike through the one reader: it never
//! panics; an accepted file gives well-formed trees, the same map read with or without its colours, and a
//! map (and colours) that ktree writes back and reads again unchanged.
#![no_main]
use ktree::io::{read_color_ot_map, read_ot_map, write_color_ot_map, write_ot_map};
use ktree::map::SensorModel;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let model = SensorModel::default();
    let plain = read_ot_map(data, "fuzz", model).ok();
    if let Some(map) = &plain {
        map.log_odds()
            .check()
            .expect("a map from a reader is well formed");
        let mut bytes = Vec::new();
        write_ot_map(&mut bytes, map).expect("a map is written");
        let back = read_ot_map(&bytes, "written", model).expect("what ktree writes reads");
        assert_eq!(&back, map);
    }
    if let Ok((map, colours)) = read_color_ot_map(data, "fuzz", model) {
        assert_eq!(plain.as_ref(), Some(&map), "the colours change the map");
        colours
            .check()
            .expect("a colour tree from a reader is well formed");
        let mut bytes = Vec::new();
        write_color_ot_map(&mut bytes, &map, &colours).expect("a file's colours are its map's");
        let back = read_color_ot_map(&bytes, "written", model).expect("what ktree writes reads");
        assert_eq!(back, (map, colours));
    }
});
