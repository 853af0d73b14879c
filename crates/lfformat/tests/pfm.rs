//! PFM: byte layout against a hand-written file, round trips, orientation, errors.

use std::path::Path;

use lfformat::Error;
use lfformat::pfm::{FloatImage, decode_pfm, encode_pfm, read_pfm, write_pfm};

/// 2×2 image, top row (1, 2), bottom row (3, 4).
fn two_by_two() -> FloatImage {
    FloatImage::new(2, 2, vec![1.0, 2.0, 3.0, 4.0])
}

/// The expected file, written out by hand: header, then the BOTTOM row first, little-endian.
fn two_by_two_file() -> Vec<u8> {
    let mut bytes = b"Pf\n2 2\n-1\n".to_vec();
    bytes.extend_from_slice(&[0x00, 0x00, 0x40, 0x40]); // 3.0
    bytes.extend_from_slice(&[0x00, 0x00, 0x80, 0x40]); // 4.0
    bytes.extend_from_slice(&[0x00, 0x00, 0x80, 0x3f]); // 1.0
    bytes.extend_from_slice(&[0x00, 0x00, 0x00, 0x40]); // 2.0
    bytes
}

/// A 3×2 image whose values encode their position: v = 10 * y + x.
fn position_coded() -> FloatImage {
    let data = (0..2).flat_map(|y| (0..3).map(move |x| (10 * y + x) as f32));
    FloatImage::new(3, 2, data.collect())
}

fn format_error_message(result: lfformat::Result<FloatImage>, path: &Path) -> String {
    match result {
        Err(e @ Error::Format { .. }) => {
            assert_eq!(e.path(), path);
            let text = e.to_string();
            assert!(text.starts_with(&path.display().to_string()), "{text}");
            text
        }
        other => panic!("expected a format error, got {other:?}"),
    }
}

#[test]
fn encoded_bytes_match_hand_written_file() {
    assert_eq!(encode_pfm(&two_by_two()), two_by_two_file());
}

#[test]
fn decodes_hand_written_file_top_down() {
    let img = decode_pfm(&two_by_two_file(), Path::new("x.pfm")).unwrap();
    assert_eq!(img, two_by_two());
    assert_eq!(img.get(0, 0), 1.0);
    assert_eq!(img.get(1, 1), 4.0);
}

#[test]
fn decodes_big_endian_positive_scale() {
    let mut bytes = b"Pf\n2 1\n1.0\n".to_vec();
    bytes.extend_from_slice(&1.5f32.to_be_bytes());
    bytes.extend_from_slice(&(-2.0f32).to_be_bytes());
    let img = decode_pfm(&bytes, Path::new("be.pfm")).unwrap();
    assert_eq!(img.data, vec![1.5, -2.0]);
}

#[test]
fn file_round_trip_keeps_orientation() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("gt_disp_lowres.pfm");
    let img = position_coded();
    write_pfm(&path, &img).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    // First stored value is the bottom-left pixel (x 0, y 1 → 10).
    let header_len = b"Pf\n3 2\n-1\n".len();
    assert_eq!(&bytes[header_len..header_len + 4], &10.0f32.to_le_bytes());
    let back = read_pfm(&path).unwrap();
    assert_eq!(back, img);
    assert_eq!(back.get(2, 0), 2.0);
    assert_eq!(back.get(0, 1), 10.0);
}

#[test]
fn truncated_pixels_are_reported_with_path() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("short.pfm");
    let bytes = two_by_two_file();
    std::fs::write(&path, &bytes[..bytes.len() - 3]).unwrap();
    let message = format_error_message(read_pfm(&path), &path);
    assert!(message.contains("truncated"), "{message}");
}

#[test]
fn header_errors_are_specific() {
    let path = Path::new("bad.pfm");
    let cases: [(&[u8], &str); 6] = [
        (b"PF\n2 2\n-1\n", "3-channel"),
        (b"P6\n2 2\n255\n", "not a single-channel PFM"),
        (b"Pf\n2 x\n-1\n", "height \"x\""),
        (b"Pf\n2 2\n0\n", "scale"),
        (b"Pf\n2 2", "no scale"),
        (b"Pf\n2 2\n-1", "truncated PFM header"),
    ];
    for (bytes, expected) in cases {
        let message = format_error_message(decode_pfm(bytes, path), path);
        assert!(message.contains(expected), "{message:?} lacks {expected:?}");
    }
}

#[test]
fn trailing_bytes_are_rejected() {
    let mut bytes = two_by_two_file();
    bytes.push(0);
    let path = Path::new("long.pfm");
    let message = format_error_message(decode_pfm(&bytes, path), path);
    assert!(message.contains("1 unexpected bytes"), "{message}");
}

#[test]
fn missing_file_is_an_io_error_naming_it() {
    let path = Path::new("/nonexistent/dir/gt.pfm");
    match read_pfm(path) {
        Err(e @ Error::Io { .. }) => {
            assert_eq!(e.path(), path);
            let Error::Io { source, .. } = &e else {
                unreachable!()
            };
            assert_eq!(source.kind(), std::io::ErrorKind::NotFound);
            assert!(e.to_string().ends_with(&source.to_string()), "{e}");
        }
        other => panic!("expected an I/O error, got {other:?}"),
    }
}

#[test]
#[should_panic(expected = "needs 4 values")]
fn new_rejects_wrong_length() {
    FloatImage::new(2, 2, vec![0.0; 3]);
}

#[test]
fn scale_magnitude_multiplies_values_as_the_hci_toolkit_does() {
    let mut bytes = b"Pf\n2 1\n-2.5\n".to_vec();
    for v in [1.0f32, -4.0] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let img = decode_pfm(&bytes, Path::new("s.pfm")).unwrap();
    assert_eq!(img.data, vec![2.5, -10.0]);
}

#[test]
fn comment_lines_in_the_header_are_skipped() {
    let mut bytes = b"Pf\n# written by a tool\n2 1\n# scale next\n-1\n".to_vec();
    for v in [1.5f32, 3.0] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let img = decode_pfm(&bytes, Path::new("c.pfm")).unwrap();
    assert_eq!((img.width, img.height, img.data), (2, 1, vec![1.5, 3.0]));
}

#[test]
fn a_huge_garbage_header_is_not_echoed_whole() {
    let mut bytes = b"Pf\n".to_vec();
    bytes.extend(std::iter::repeat_n(b'x', 1 << 20));
    let e = decode_pfm(&bytes, Path::new("g.pfm"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("g.pfm") && e.len() < 200,
        "{} bytes: {}",
        e.len(),
        &e[..200.min(e.len())]
    );
}
