//! `gt_mpi_lowres.npz`: layout from modes, the on-disk npy checked by parsing the zip entry's
//! header and data by hand (not with npyz's reader), round trip, errors.

use std::io::Read;
use std::path::Path;

use lfformat::mpi::{CHANNELS, LOADER_LAYERS, Mpi, read_mpi_npz, write_mpi_npz};
use lfformat::{Error, Mode, ModeMap};
use npyz::WriterBuilder;
use npyz::npz::NpzWriter;

/// 2 wide, 3 tall; pixel (x, y) has `(x + y) % 3` modes with disparity `10y + x + l/4`.
fn sample_map() -> ModeMap {
    let mut map = ModeMap::new(2, 3);
    for y in 0..3 {
        for x in 0..2 {
            let modes: Vec<Mode> = (0..(x + y) % 3)
                .map(|l| Mode {
                    disparity: (10 * y + x) as f32 + l as f32 / 4.0,
                    depth: 2.0,
                    eta: 0.5,
                    eta_exact: 0.4,
                })
                .collect();
            map.push_pixel(&modes);
        }
    }
    map
}

/// One distinct colour per mode, in push order: (i, 2i, 3i).
fn colours(map: &ModeMap) -> Vec<[f32; 3]> {
    (0..map.total_modes())
        .map(|i| [i as f32, 2.0 * i as f32, 3.0 * i as f32])
        .collect()
}

/// The `.npy` header dict and the little-endian f32 payload of `mpi.npy` in the zip.
fn raw_npy(path: &Path) -> (String, Vec<f32>) {
    let mut zip = npyz::zip::ZipArchive::new(std::fs::File::open(path).unwrap()).unwrap();
    let mut bytes = Vec::new();
    zip.by_name("mpi.npy")
        .unwrap()
        .read_to_end(&mut bytes)
        .unwrap();
    assert_eq!(&bytes[..6], b"\x93NUMPY");
    let (header_len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        _ => (
            u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize,
            12,
        ),
    };
    let header = String::from_utf8(bytes[start..start + header_len].to_vec()).unwrap();
    let data = bytes[start + header_len..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    (header, data)
}

/// The `shape` tuple of an npy header dict, e.g. `(3, 2, 2, 5, )`.
fn shape_of(header: &str) -> Vec<u64> {
    let tuple = header
        .split("'shape': (")
        .nth(1)
        .unwrap()
        .split(')')
        .next()
        .unwrap();
    tuple
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().unwrap())
        .collect()
}

/// Bitwise equality so that NaN padding compares equal.
fn same_bits(a: &[f32], b: &[f32]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[test]
fn from_modes_lays_out_layers_colours_and_nan_padding() {
    let map = sample_map();
    let mpi = Mpi::from_modes(&map, Some(&colours(&map)), 0);
    assert_eq!((mpi.width, mpi.height, mpi.layers), (2, 3, 2));
    assert_eq!(mpi.data.len(), 2 * 3 * 2 * CHANNELS);
    // Push order: (0,0) none, (1,0) one [mode 0], (0,1) one [1], (1,1) two [2, 3].
    assert_eq!(mpi.get(1, 1, 1), [3.0, 6.0, 9.0, 0.5, 11.25]);
    assert_eq!(mpi.get(1, 0, 0), [0.0, 0.0, 0.0, 0.5, 1.0]);
    assert!(mpi.get(1, 0, 1).iter().all(|v| v.is_nan()));
    assert!(mpi.get(0, 0, 0).iter().all(|v| v.is_nan()));
    let uncoloured = Mpi::from_modes(&map, None, 0);
    assert_eq!(uncoloured.get(1, 1, 1), [0.0, 0.0, 0.0, 0.5, 11.25]);
}

/// Files for the thesis' loader have at least its 12 layers whatever the scene's mode count
/// (it batches scenes together, so one shape for all), the extra layers NaN, the real ones
/// unchanged.
#[test]
fn from_modes_pads_to_the_loaders_twelve_layers() {
    let map = sample_map();
    let bare = Mpi::from_modes(&map, Some(&colours(&map)), 0);
    let padded = Mpi::from_modes(&map, Some(&colours(&map)), LOADER_LAYERS);
    assert_eq!((padded.width, padded.height, padded.layers), (2, 3, 12));
    for (x, y) in [(0, 0), (1, 0), (0, 1), (1, 1), (0, 2), (1, 2)] {
        for l in 0..12 {
            let v = padded.get(x, y, l);
            match l < bare.layers {
                true => assert!(same_bits(&v, &bare.get(x, y, l))),
                false => assert!(v.iter().all(|c| c.is_nan()), "({x}, {y}) layer {l}"),
            }
        }
    }
    // A floor below the mode count drops nothing.
    assert_eq!(Mpi::from_modes(&map, None, 1).layers, 2);
}

#[test]
fn npz_on_disk_is_c_order_float32_bottom_up() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("gt_mpi_lowres.npz");
    let map = sample_map();
    let mpi = Mpi::from_modes(&map, Some(&colours(&map)), 0);
    write_mpi_npz(&path, &mpi).unwrap();
    let (header, data) = raw_npy(&path);
    assert!(header.contains("'descr': '<f4'"), "{header}");
    assert!(header.contains("'fortran_order': False"), "{header}");
    assert_eq!(shape_of(&header), [3, 2, 2, 5], "{header}");
    assert_eq!(data.len(), 3 * 2 * 2 * CHANNELS);
    // The first stored row is the bottom image row (y = 2): pixel (0, 2) has two modes.
    assert_eq!(data[3..5], [0.5, 20.0]);
    assert_eq!(data[8..10], [0.5, 20.25]);
    // The last stored row is the top row: its pixel (0, 0) has no modes at all.
    let top = 2 * 2 * 2 * CHANNELS;
    assert!(data[top..top + 2 * CHANNELS].iter().all(|v| v.is_nan()));
    assert_eq!(data[top + 2 * CHANNELS + 4], 1.0);
}

#[test]
fn npz_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("gt_mpi_lowres.npz");
    let map = sample_map();
    let mpi = Mpi::from_modes(&map, Some(&colours(&map)), 0);
    write_mpi_npz(&path, &mpi).unwrap();
    let back = read_mpi_npz(&path).unwrap();
    assert_eq!((back.width, back.height, back.layers), (2, 3, 2));
    assert!(same_bits(&back.data, &mpi.data));
}

/// Writes an npz holding one float32 array `name` of `shape`, filled with zeros.
fn write_other_npz(path: &Path, name: &str, shape: &[u64]) {
    let mut npz = NpzWriter::create(path).unwrap();
    let mut array = npz
        .array::<f32>(name, Default::default())
        .unwrap()
        .default_dtype()
        .shape(shape)
        .begin_nd()
        .unwrap();
    array
        .extend(std::iter::repeat_n(
            0.0,
            shape.iter().product::<u64>() as usize,
        ))
        .unwrap();
    array.finish().unwrap();
}

fn format_error_text(path: &Path) -> String {
    let err = read_mpi_npz(path).unwrap_err();
    assert!(matches!(err, Error::Format { .. }), "{err:?}");
    assert_eq!(err.path(), path);
    err.to_string()
}

#[test]
fn wrong_key_or_shape_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.npz");
    write_other_npz(&path, "depth", &[2, 2]);
    assert!(format_error_text(&path).contains("no array named \"mpi\""));
    write_other_npz(&path, "mpi", &[2, 2, 1, 4]);
    assert!(format_error_text(&path).contains("shape [2, 2, 1, 4]"));
}

#[test]
fn corrupt_or_truncated_archives_are_format_errors() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("gt_mpi_lowres.npz");
    std::fs::write(&path, b"not a zip archive at all").unwrap();
    format_error_text(&path);
    let map = sample_map();
    write_mpi_npz(&path, &Mpi::from_modes(&map, None, 0)).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() - 30]).unwrap();
    format_error_text(&path);
}

/// Manual cross-check with numpy: `cargo test -p lfformat --test mpi -- --ignored`, with
/// `LFFORMAT_PYTHON` naming a Python that has numpy (default `python3`).
#[test]
#[ignore = "needs python3 with numpy"]
fn numpy_reads_shape_dtype_and_flip() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("gt_mpi_lowres.npz");
    let map = sample_map();
    write_mpi_npz(&path, &Mpi::from_modes(&map, Some(&colours(&map)), 0)).unwrap();
    let script = "import sys, numpy as np\n\
        a = np.load(sys.argv[1])['mpi']\n\
        assert a.dtype == np.float32 and a.shape == (3, 2, 2, 5), (a.dtype, a.shape)\n\
        a = a[::-1]\n\
        assert a[1, 1, 1].tolist() == [3.0, 6.0, 9.0, 0.5, 11.25], a[1, 1, 1]\n\
        assert np.isnan(a[0, 0]).all()\n";
    let status =
        std::process::Command::new(std::env::var("LFFORMAT_PYTHON").unwrap_or("python3".into()))
            .args(["-c", script])
            .arg(&path)
            .status()
            .unwrap();
    assert!(status.success());
}
