//! ModeMap storage and `modes.exr`: layout checked with the exr crate directly, round trips
//! with 12 modes (mode10/mode11 sort before mode2 on disk), tolerant and failing reads.

use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer, LayerAttributes, WritableImage,
    read_first_flat_layer_from_file,
};
use lfformat::modes::{
    read_modes_exr, read_modes_exr_with_surfaces, write_modes_exr, write_modes_exr_with_surfaces,
};
use lfformat::{Error, Mode, ModeMap, ModeSurface};

fn mode(disparity: f32, eta: f32) -> Mode {
    Mode {
        disparity,
        depth: 1.0 / (1.0 + disparity),
        eta,
        eta_exact: eta * 0.5,
    }
}

/// 3×2 map, no two pixels alike: pixel (x, y) holds `x + 3y` modes except the top-right
/// pixel, which holds 12 (slots 0..11, so the file has mode10 and mode11).
fn sample_map() -> ModeMap {
    let mut map = ModeMap::new(3, 2);
    for y in 0..2 {
        for x in 0..3 {
            let count = if (x, y) == (2, 0) { 12 } else { x + 3 * y };
            let modes: Vec<Mode> = (0..count)
                .map(|k| mode((10 * y + x) as f32 + k as f32 / 16.0, 0.05))
                .collect();
            map.push_pixel(&modes);
        }
    }
    map
}

/// Samples of channel `name` in a flat layer, as f32.
fn channel(layer: &Layer<AnyChannels<FlatSamples>>, name: &str) -> Vec<f32> {
    let found = layer
        .channel_data
        .list
        .iter()
        .find(|c| c.name.to_string() == name);
    found
        .unwrap_or_else(|| panic!("no channel {name}"))
        .sample_data
        .values_as_f32()
        .collect()
}

/// Writes one layer with the given channels, bypassing the crate's writer.
fn write_raw_exr(path: &Path, size: (usize, usize), channels: Vec<(&str, Vec<f32>)>) {
    let list: Vec<_> = channels
        .into_iter()
        .map(|(n, v)| AnyChannel::new(n, FlatSamples::F32(v)))
        .collect();
    let layer = Layer::new(
        size,
        LayerAttributes::default(),
        Encoding::UNCOMPRESSED,
        AnyChannels::sort(list.into()),
    );
    Image::from_layer(layer).write().to_file(path).unwrap();
}

#[test]
fn map_stores_pixels_in_order() {
    let map = sample_map();
    assert!(map.is_complete());
    assert_eq!(map.max_modes(), 12);
    assert_eq!(map.total_modes(), 12 + 1 + 3 + 4 + 5);
    assert_eq!(map.pixel(0, 0), &[] as &[Mode]);
    assert_eq!(map.pixel(1, 1).len(), 4);
    assert_eq!(map.pixel(1, 1)[2].disparity, 11.0 + 2.0 / 16.0);
    assert_eq!(
        map.pixels().map(<[Mode]>::len).collect::<Vec<_>>(),
        [0, 1, 12, 3, 4, 5]
    );
}

#[test]
fn append_joins_row_tiles() {
    let whole = sample_map();
    let mut joined = ModeMap::new(3, 0);
    for y in 0..2 {
        let mut tile = ModeMap::new(3, 1);
        for x in 0..3 {
            tile.push_pixel(whole.pixel(x, y));
        }
        joined.append(tile);
    }
    assert_eq!(joined, whole);
}

#[test]
#[should_panic(expected = "all pixels already pushed")]
fn pushing_too_many_pixels_panics() {
    let mut map = ModeMap::new(1, 1);
    map.push_pixel(&[]);
    map.push_pixel(&[]);
}

#[test]
fn exr_layout_on_disk() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("modes.exr");
    write_modes_exr(&path, &sample_map()).unwrap();
    let image = read_first_flat_layer_from_file(&path).unwrap();
    let layer = &image.layer_data;
    assert_eq!((layer.size.width(), layer.size.height()), (3, 2));
    assert_eq!(layer.channel_data.list.len(), 12 * 4);
    // mode11 exists only at the top-right pixel (index 2 of the top row, no flip).
    let d11 = channel(layer, "mode11.disparity");
    assert_eq!(d11[2], 2.0 + 11.0 / 16.0);
    assert!(d11[0].is_nan() && d11[5].is_nan());
    assert_eq!(
        channel(layer, "mode11.eta"),
        [0.0, 0.0, 0.05, 0.0, 0.0, 0.0]
    );
    assert_eq!(
        channel(layer, "mode0.eta_exact"),
        [0.0, 0.025, 0.025, 0.025, 0.025, 0.025]
    );
    assert!(channel(layer, "mode0.depth")[0].is_nan());
}

#[test]
fn exr_round_trip_with_twelve_modes() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("modes.exr");
    let map = sample_map();
    write_modes_exr(&path, &map).unwrap();
    let back = read_modes_exr(&path).unwrap();
    assert_eq!(back, map);
    assert_eq!(back.pixel(2, 0)[10].disparity, 2.0 + 10.0 / 16.0);
}

/// Surfaces travel with their modes (ids past 2^24, where f32 would round them, included);
/// the depth-only reader reads the same map from the larger file, and a file without surface
/// channels has no surfaces.
#[test]
fn exr_round_trip_with_surfaces() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("modes.exr");
    let map = sample_map();
    let surfaces: Vec<ModeSurface> = (0..map.total_modes() as u32)
        .map(|i| ModeSurface {
            normal: [i as f32 / 64.0, -0.5, 0.25],
            object: i + 1,
            material: (1 << 24) + 1 + i,
            class: 7,
        })
        .collect();
    write_modes_exr_with_surfaces(&path, &map, &surfaces).unwrap();
    let (back, back_surfaces) = read_modes_exr_with_surfaces(&path).unwrap();
    assert_eq!(back, map);
    assert_eq!(back_surfaces, Some(surfaces));
    assert_eq!(read_modes_exr(&path).unwrap(), map);
    let image = read_first_flat_layer_from_file(&path).unwrap();
    let layer = &image.layer_data;
    assert!(channel(layer, "mode11.normal.X")[0].is_nan(), "unused slot");
    write_modes_exr(&path, &map).unwrap();
    assert_eq!(read_modes_exr_with_surfaces(&path).unwrap(), (map, None));
}

/// A file with some surface channels but not all is refused, naming the missing one.
#[test]
fn a_partial_set_of_surface_channels_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("modes.exr");
    let channels = vec![
        ("mode0.disparity", vec![1.0]),
        ("mode0.depth", vec![2.0]),
        ("mode0.eta", vec![1.0]),
        ("mode0.eta_exact", vec![1.0]),
        ("mode0.normal.X", vec![0.0]),
    ];
    write_raw_exr(&path, (1, 1), channels);
    let e = read_modes_exr_with_surfaces(&path).unwrap_err().to_string();
    assert!(
        e.contains("mode0.normal.Y") && e.contains("modes.exr"),
        "{e}"
    );
}

#[test]
fn empty_map_still_writes_one_slot() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("modes.exr");
    let mut map = ModeMap::new(2, 1);
    map.push_pixel(&[]);
    map.push_pixel(&[]);
    write_modes_exr(&path, &map).unwrap();
    let image = read_first_flat_layer_from_file(&path).unwrap();
    assert_eq!(image.layer_data.channel_data.list.len(), 4);
    assert_eq!(read_modes_exr(&path).unwrap(), map);
}

#[test]
fn reader_matches_by_name_skips_padding_and_ignores_other_channels() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("other.exr");
    // Slot 0 is padding at both pixels, slot 1 holds one mode with only eta_exact > 0.
    write_raw_exr(
        &path,
        (2, 1),
        vec![
            ("mode1.eta_exact", vec![0.0, 0.25]),
            ("R", vec![9.0, 9.0]),
            ("mode0.depth", vec![f32::NAN, f32::NAN]),
            ("mode1.depth", vec![f32::NAN, 4.0]),
            ("mode0.eta", vec![0.0, 0.0]),
            ("mode1.disparity", vec![f32::NAN, -1.5]),
            ("mode0.disparity", vec![f32::NAN, f32::NAN]),
            ("mode1.eta", vec![0.0, 0.0]),
            ("mode0.eta_exact", vec![0.0, 0.0]),
            ("mode0.note", vec![1.0, 1.0]),
        ],
    );
    let map = read_modes_exr(&path).unwrap();
    assert_eq!(map.pixel(0, 0), &[] as &[Mode]);
    let expected = Mode {
        disparity: -1.5,
        depth: 4.0,
        eta: 0.0,
        eta_exact: 0.25,
    };
    assert_eq!(map.pixel(1, 0), &[expected]);
}

#[test]
fn missing_channel_is_a_format_error_naming_file_and_channel() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("partial.exr");
    write_raw_exr(
        &path,
        (1, 1),
        vec![
            ("mode0.disparity", vec![1.0]),
            ("mode0.depth", vec![1.0]),
            ("mode0.eta_exact", vec![1.0]),
        ],
    );
    let err = read_modes_exr(&path).unwrap_err();
    assert!(matches!(err, Error::Format { .. }), "{err:?}");
    let text = err.to_string();
    assert!(
        text.contains("partial.exr") && text.contains("missing channel mode0.eta"),
        "{text}"
    );
}

#[test]
fn truncated_exr_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("modes.exr");
    write_modes_exr(&path, &sample_map()).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    let err = read_modes_exr(&path).unwrap_err();
    assert_eq!(err.path(), path);
    assert!(err.to_string().starts_with(&path.display().to_string()));
}
