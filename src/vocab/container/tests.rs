use super::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::json;

const NAME: &str = "model.vocab";

/// A NaN with a payload and the sign bit set, to check bits survive.
fn odd_nan() -> f64 {
    f64::from_bits(0xfff8_0000_dead_beef)
}

fn sample() -> Container {
    let mut c = Container::new(json!({"kind": "test", "primitives": 3, "nested": {"b": [1, 2], "a": null}}));
    c.push("mean", vec![1.0, -2.5, 3.25]);
    c.push("empty", vec![]);
    c.push("special", vec![f64::NAN, odd_nan(), f64::INFINITY, f64::NEG_INFINITY, -0.0, 0.0, f64::MIN_POSITIVE]);
    c.push("ramp", (0..100).map(|i| i as f64 * 0.1).collect());
    c
}

fn bits(values: &[f64]) -> Vec<u64> {
    values.iter().map(|v| v.to_bits()).collect()
}

fn header_len(bytes: &[u8]) -> usize {
    u64::from_le_bytes(bytes[HEADER_LEN_AT..HEADER_AT].try_into().unwrap()) as usize
}

/// Recomputes the trailing checksum of a (patched) file.
fn reseal(bytes: &mut [u8]) {
    let at = bytes.len() - CHECKSUM_LEN;
    let crc = crc32fast::hash(&bytes[..at]);
    bytes[at..].copy_from_slice(&crc.to_le_bytes());
}

/// A file with the given version, raw header bytes and data, correctly
/// padded and with a valid checksum.
fn assemble(version: u32, header: &[u8], data: &[f64]) -> Vec<u8> {
    let mut bytes = MAGIC.to_vec();
    bytes.extend_from_slice(&version.to_le_bytes());
    bytes.extend_from_slice(&(header.len() as u64).to_le_bytes());
    bytes.extend_from_slice(header);
    bytes.resize(bytes.len() + padding_after(header.len() as u64), 0);
    for v in data {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes.extend_from_slice(&[0; 4]);
    reseal(&mut bytes);
    bytes
}

fn error_of(result: Result<Container, ContainerError>) -> ContainerError {
    match result {
        Ok(_) => panic!("expected an error, read a container"),
        Err(e) => e,
    }
}

/// Reads `bytes` expecting an error whose message names the file and
/// contains `expected`; returns the error's kind.
fn refused(bytes: &[u8], expected: &str) -> ContainerErrorKind {
    let err = error_of(Container::from_bytes(bytes, NAME));
    let message = err.to_string();
    assert!(message.starts_with(&format!("{NAME}: ")), "message does not name the file: {message}");
    assert!(message.contains(expected), "message `{message}` does not contain `{expected}`");
    *err.kind
}

#[test]
fn round_trip_keeps_header_names_order_and_every_bit() {
    let original = sample();
    let bytes = original.to_bytes().unwrap();
    let read = Container::from_bytes(&bytes, NAME).unwrap();
    assert_eq!(read.header, original.header, "the header comes back without the container's keys");
    assert_eq!(read.names().collect::<Vec<_>>(), ["mean", "empty", "special", "ramp"]);
    for (name, values) in original.arrays() {
        assert_eq!(bits(read.array(name).unwrap()), bits(values), "array `{name}`");
    }
    assert_eq!(read.array("empty").unwrap().len(), 0);
    let special = read.array("special").unwrap();
    assert_eq!(special[1].to_bits(), 0xfff8_0000_dead_beef, "NaN payload and sign kept");
    assert!(special[4].is_sign_negative() && special[4] == 0.0, "-0.0 kept");
    assert_eq!(read.array("missing"), None);
}

#[test]
fn container_without_arrays_round_trips() {
    let c = Container::new(json!({}));
    let bytes = c.to_bytes().unwrap();
    assert_eq!(bytes.len(), 60, "the smallest valid file, as documented");
    let read = Container::from_bytes(&bytes, NAME).unwrap();
    assert_eq!(read.header, json!({}));
    assert_eq!(read.names().count(), 0);
}

#[test]
fn bytes_match_the_documented_layout_exactly() {
    let mut c = Container::new(json!({"kind": "demo"}));
    c.push("mean", vec![1.0, -2.0]);
    let bytes = c.to_bytes().unwrap();
    let header = br#"{"arrays":[{"len":2,"name":"mean"}],"data_bytes":16,"kind":"demo"}"#;
    let mut expected = b"imitate-vocab\n".to_vec();
    expected.extend_from_slice(&[2, 0, 0, 0]);
    expected.extend_from_slice(&(header.len() as u64).to_le_bytes());
    expected.extend_from_slice(header);
    // 26 + 66 = 92 bytes so far: 4 zero bytes pad the data to offset 96.
    assert_eq!(header.len(), 66);
    expected.extend_from_slice(&[0, 0, 0, 0]);
    expected.extend_from_slice(&1.0f64.to_le_bytes());
    expected.extend_from_slice(&(-2.0f64).to_le_bytes());
    let crc = crc32fast::hash(&expected);
    expected.extend_from_slice(&crc.to_le_bytes());
    assert_eq!(bytes, expected);
    assert_eq!(bytes.len(), 26 + 66 + 4 + 16 + 4);
}

#[test]
fn checksum_is_the_standard_crc32() {
    assert_eq!(crc32fast::hash(b"123456789"), 0xCBF4_3926);
}

#[test]
fn same_container_gives_same_bytes_whatever_the_key_order() {
    let a = sample().to_bytes().unwrap();
    assert_eq!(a, sample().to_bytes().unwrap());
    // The same header built with keys inserted in another order.
    let mut header = Map::new();
    header.insert("primitives".into(), json!(3));
    header.insert("nested".into(), json!({"a": null, "b": [1, 2]}));
    header.insert("kind".into(), json!("test"));
    let mut other = Container::new(Value::Object(header));
    for (name, values) in sample().arrays() {
        other.push(name, values.to_vec());
    }
    assert_eq!(a, other.to_bytes().unwrap());
    // Reading and writing again changes nothing.
    let again = Container::from_bytes(&a, NAME).unwrap().to_bytes().unwrap();
    assert_eq!(a, again);
}

#[test]
fn every_array_starts_8_byte_aligned_for_every_padding() {
    let mut paddings = HashSet::new();
    for extra in 0..16 {
        let mut c = Container::new(json!({"text": "x".repeat(extra)}));
        c.push("one", vec![1.5]);
        c.push("none", vec![]);
        c.push("three", vec![2.5, 3.5, 4.5]);
        c.push("last", vec![5.5]);
        let bytes = c.to_bytes().unwrap();
        let h = header_len(&bytes);
        let padding = padding_after(h as u64);
        paddings.insert(padding);
        assert!(bytes[HEADER_AT + h..HEADER_AT + h + padding].iter().all(|&b| b == 0), "padding is zeros");
        let mut at = HEADER_AT + h + padding;
        for (name, values) in c.arrays() {
            assert_eq!(at % 8, 0, "array `{name}` starts at {at}");
            for (i, v) in values.iter().enumerate() {
                let stored = f64::from_le_bytes(bytes[at + 8 * i..at + 8 * i + 8].try_into().unwrap());
                assert_eq!(stored, *v, "array `{name}` value {i} at its offset");
            }
            at += 8 * values.len();
        }
        assert_eq!(at + CHECKSUM_LEN, bytes.len(), "the checksum ends the file");
    }
    assert_eq!(paddings.len(), 8, "every padding 0..=7 was exercised: {paddings:?}");
}

#[test]
fn large_arrays_round_trip_across_write_chunks() {
    let n = 3 * WRITE_CHUNK + 5;
    let mut c = Container::new(json!({"large": true}));
    c.push("a", (0..n).map(|i| (i as f64).sin()).collect());
    c.push("b", (0..1_000_003).map(|i| i as f64 * 1e-3).collect());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("large.vocab");
    c.write(&path).unwrap();
    assert_eq!(fs::metadata(&path).unwrap().len(), c.to_bytes().unwrap().len() as u64);
    let read = Container::read(&path).unwrap();
    assert_eq!(bits(read.array("a").unwrap()), bits(c.array("a").unwrap()));
    assert_eq!(read.array("b").unwrap().len(), 1_000_003);
    assert_eq!(read.array("b").unwrap()[1_000_002], 1_000_002.0 * 1e-3);
}

#[test]
fn take_moves_an_array_out_and_array_finds_by_name() {
    let mut c = sample();
    assert_eq!(c.array("mean"), Some(&[1.0, -2.5, 3.25][..]));
    assert_eq!(c.take("mean"), Some(vec![1.0, -2.5, 3.25]));
    assert_eq!(c.array("mean"), None);
    assert_eq!(c.take("mean"), None);
    assert_eq!(c.names().collect::<Vec<_>>(), ["empty", "special", "ramp"]);
}

#[test]
fn write_then_read_gives_the_same_file_and_leaves_no_temporary() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("v.vocab");
    let c = sample();
    c.write(&path).unwrap();
    assert_eq!(fs::read(&path).unwrap(), c.to_bytes().unwrap());
    let read = Container::read(&path).unwrap();
    assert_eq!(read.header, c.header);
    assert_eq!(bits(read.array("special").unwrap()), bits(c.array("special").unwrap()));
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn failed_write_into_missing_directory_leaves_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("no-such-dir").join("v.vocab");
    let err = sample().write(&path).unwrap_err();
    assert!(matches!(*err.kind, ContainerErrorKind::Write(_)), "{err}");
    assert!(err.to_string().starts_with(&format!("{}: cannot write: ", path.display())), "{err}");
    assert!(!path.exists());
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn header_with_reserved_key_is_refused_and_keeps_the_existing_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("v.vocab");
    fs::write(&path, b"old").unwrap();
    for key in RESERVED_KEYS {
        let mut header = Map::new();
        header.insert(key.to_string(), json!(1));
        let c = Container::new(Value::Object(header));
        assert_eq!(c.to_bytes().unwrap_err(), InvalidContainer::ReservedKey { key });
        let err = c.write(&path).unwrap_err();
        assert!(matches!(*err.kind, ContainerErrorKind::Invalid(InvalidContainer::ReservedKey { .. })));
        assert_eq!(
            err.to_string(),
            format!(
                "{}: cannot write: the header has the key `{key}`, which the container writes itself",
                path.display()
            )
        );
    }
    assert_eq!(fs::read(&path).unwrap(), b"old");
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn header_that_is_not_an_object_and_duplicate_names_are_refused() {
    assert_eq!(
        Container::new(json!([1, 2])).to_bytes().unwrap_err(),
        InvalidContainer::HeaderNotObject { found: "a list" }
    );
    let mut c = Container::new(json!({}));
    c.push("x", vec![1.0]);
    c.push("x", vec![2.0]);
    assert_eq!(c.to_bytes().unwrap_err(), InvalidContainer::DuplicateArray { name: "x".into() });
}

#[test]
fn missing_file_is_a_read_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("absent.vocab");
    let err = error_of(Container::read(&path));
    assert!(matches!(*err.kind, ContainerErrorKind::Read(_)));
    assert!(err.to_string().starts_with(&format!("{}: cannot read: ", path.display())), "{err}");
}

#[test]
fn other_files_are_not_vocabulary_files_and_the_message_shows_their_start() {
    let cases: [(&[u8], &str); 6] = [
        (b"HIERARCHY\nROOT Hips\n", "not a vocabulary file: it starts with `HIERARCHY`"),
        (b"", "not a vocabulary file: the file is empty"),
        (
            b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR",
            "not a vocabulary file: it starts with binary data (89 50 4e 47 0d 0a 1a 0a …)",
        ),
        (b"  {\"arrays\": []}", "it starts with `{\"arrays\": []}`"),
        (b"imitate-vocab\r\n\x01\0\0\0", "but then byte 0x0d instead of a line feed"),
        (b"imitate-vocaX\n", "it starts with `imitate-vocaX`"),
    ];
    for (bytes, expected) in cases {
        let kind = refused(bytes, expected);
        assert!(matches!(kind, ContainerErrorKind::NotVocab { .. }), "{kind}");
    }
    let long = "x".repeat(100);
    refused(long.as_bytes(), &format!("it starts with `{}…`", "x".repeat(40)));
}

#[test]
fn newer_version_asks_to_update_and_version_zero_is_unknown() {
    let mut bytes = sample().to_bytes().unwrap();
    bytes[VERSION_AT..HEADER_LEN_AT].copy_from_slice(&3u32.to_le_bytes());
    reseal(&mut bytes);
    let kind = refused(&bytes, "written by a newer imitate (format version 3; this version reads 2): update imitate");
    assert!(matches!(kind, ContainerErrorKind::NewerVersion { version: 3 }));

    bytes[VERSION_AT..HEADER_LEN_AT].copy_from_slice(&0u32.to_le_bytes());
    reseal(&mut bytes);
    let kind = refused(&bytes, "unknown format version 0 (this version reads 2");
    assert!(matches!(kind, ContainerErrorKind::UnknownVersion { version: 0 }));
}

#[test]
fn a_vocabulary_of_the_earlier_joint_space_asks_to_be_built_again() {
    let mut bytes = sample().to_bytes().unwrap();
    bytes[VERSION_AT..HEADER_LEN_AT].copy_from_slice(&1u32.to_le_bytes());
    reseal(&mut bytes);
    let kind = refused(&bytes, "format version 1, whose poses are in an earlier joint space");
    assert!(matches!(kind, ContainerErrorKind::OlderJointSpace { version: 1 }), "{kind}");
    assert!(kind.to_string().contains("imitate vocab build"), "{kind}");
}

#[test]
fn newer_version_is_reported_even_if_the_rest_is_unreadable() {
    // A newer format may change everything after the version.
    let mut bytes = MAGIC.to_vec();
    bytes.extend_from_slice(&3u32.to_le_bytes());
    bytes.extend_from_slice(b"whatever version 3 holds");
    assert!(matches!(refused(&bytes, "newer imitate"), ContainerErrorKind::NewerVersion { version: 3 }));
}

#[test]
fn every_cut_of_a_valid_file_is_refused_as_truncated() {
    let bytes = sample().to_bytes().unwrap();
    let h = header_len(&bytes);
    assert_eq!(refused(&bytes[..0], "the file is empty").to_string(), "not a vocabulary file: the file is empty");
    for cut in 1..bytes.len() {
        let kind = refused(&bytes[..cut], &format!("truncated: {cut} bytes, "));
        let ContainerErrorKind::Truncated { len, needed } = kind else { panic!("cut at {cut}: {kind}") };
        assert_eq!(len, cut as u64);
        let expected = if cut < HEADER_AT {
            Needed::Minimum(MIN_FILE_LEN)
        } else if cut < HEADER_AT + h + CHECKSUM_LEN {
            Needed::HeaderAtLeast((HEADER_AT + h + CHECKSUM_LEN) as u128)
        } else {
            Needed::Exactly(bytes.len() as u128)
        };
        assert_eq!(needed, expected, "cut at {cut}");
    }
    let message = error_of(Container::from_bytes(&bytes[..bytes.len() - 1], NAME)).to_string();
    assert_eq!(message, format!("{NAME}: truncated: {} bytes, the header describes {}", bytes.len() - 1, bytes.len()));
}

#[test]
fn every_single_byte_change_is_refused_for_the_right_reason() {
    let bytes = sample().to_bytes().unwrap();
    let header_end = HEADER_AT + header_len(&bytes);
    for at in 0..bytes.len() {
        for flip in [0x01u8, 0x02, 0x10, 0x80, 0xff, 0x5a] {
            let mut changed = bytes.clone();
            changed[at] ^= flip;
            let err = error_of(Container::from_bytes(&changed, NAME));
            assert!(err.to_string().starts_with(NAME));
            let kind = *err.kind;
            let right = match at {
                _ if at < VERSION_AT => matches!(kind, ContainerErrorKind::NotVocab { .. }),
                _ if at < HEADER_LEN_AT => {
                    match u32::from_le_bytes(changed[VERSION_AT..HEADER_LEN_AT].try_into().unwrap()) {
                        0 => matches!(kind, ContainerErrorKind::UnknownVersion { version: 0 }),
                        1 => matches!(kind, ContainerErrorKind::OlderJointSpace { version: 1 }),
                        v => matches!(kind, ContainerErrorKind::NewerVersion { version } if version == v),
                    }
                }
                // A header running past the file is a cut file; within the file,
                // a shorter header cuts the JSON and a longer one takes in the
                // padding's zero bytes after it.
                _ if at < HEADER_AT => {
                    if (HEADER_AT + CHECKSUM_LEN) as u128 + header_len(&changed) as u128 > changed.len() as u128 {
                        matches!(kind, ContainerErrorKind::Truncated { needed: Needed::HeaderAtLeast(_), .. })
                    } else {
                        matches!(kind, ContainerErrorKind::BadHeader { .. })
                    }
                }
                _ if at < header_end => {
                    matches!(kind, ContainerErrorKind::BadHeader { .. } | ContainerErrorKind::Corrupt { .. })
                }
                _ => matches!(kind, ContainerErrorKind::Corrupt { .. }),
            };
            assert!(right, "byte {at} ^ {flip:#04x}: {kind}");
        }
    }
}

#[test]
fn corrupt_data_is_reported_with_both_checksums() {
    let mut bytes = sample().to_bytes().unwrap();
    let stored = u32::from_le_bytes(bytes[bytes.len() - 4..].try_into().unwrap());
    let last_value = bytes.len() - 5;
    bytes[last_value] ^= 0x40;
    let computed = crc32fast::hash(&bytes[..bytes.len() - 4]);
    let kind = refused(
        &bytes,
        &format!("corrupt: checksum {stored:#010x} stored in the file does not match {computed:#010x} computed"),
    );
    assert!(matches!(kind, ContainerErrorKind::Corrupt { .. }));
}

#[test]
fn bytes_after_the_checksum_are_refused_as_trailing() {
    let mut bytes = sample().to_bytes().unwrap();
    let end = bytes.len();
    bytes.extend_from_slice(b"junk");
    let kind =
        refused(&bytes, &format!("4 trailing bytes after the checksum, which should end the file at byte {end}"));
    assert!(matches!(kind, ContainerErrorKind::TrailingBytes { extra: 4, .. }));
    // Two files glued together: the second is trailing bytes of the first.
    let mut twice = sample().to_bytes().unwrap();
    twice.extend_from_slice(&sample().to_bytes().unwrap());
    assert!(matches!(refused(&twice, "trailing bytes"), ContainerErrorKind::TrailingBytes { .. }));
}

#[test]
fn huge_header_lengths_are_truncation_not_allocation() {
    let valid = sample().to_bytes().unwrap();
    for huge in [1_000_000_000_000_000_000u64, u64::MAX, u64::MAX - 25, (1 << 63) + 1] {
        let mut bytes = valid.clone();
        bytes[HEADER_LEN_AT..HEADER_AT].copy_from_slice(&huge.to_le_bytes());
        let expected = huge as u128 + 30;
        let kind = refused(&bytes, &format!("the header length says at least {expected}"));
        assert!(
            matches!(kind, ContainerErrorKind::Truncated { needed: Needed::HeaderAtLeast(n), .. } if n == expected)
        );
    }
}

#[test]
fn malformed_headers_are_refused_each_with_its_reason() {
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (b"{\"arrays\":[],\"data_bytes\":0,\"k\":\"\xff\"}".to_vec(), "not UTF-8 (invalid byte at header offset 33)"),
        (b"{\"arrays\":[],".to_vec(), "not valid JSON (EOF while parsing"),
        (b"[1,2]".to_vec(), "the JSON header is a list, not an object"),
        (b"{\"data_bytes\":0}".to_vec(), "has no `arrays` list"),
        (b"{\"arrays\":{},\"data_bytes\":0}".to_vec(), "`arrays` is an object, not a list"),
        (b"{\"arrays\":[]}".to_vec(), "has no `data_bytes`"),
        (b"{\"arrays\":[],\"data_bytes\":-1}".to_vec(), "`data_bytes` is not a whole number: -1"),
        (b"{\"arrays\":[3],\"data_bytes\":0}".to_vec(), "`arrays` entry 0 is a number, not an object"),
        (b"{\"arrays\":[{\"len\":0}],\"data_bytes\":0}".to_vec(), "entry 0 has no `name` string"),
        (
            b"{\"arrays\":[{\"name\":\"a\"}],\"data_bytes\":0}".to_vec(),
            "entry 0 (`a`) has no `len` that is a whole number",
        ),
        (
            b"{\"arrays\":[{\"name\":\"a\",\"len\":1.5}],\"data_bytes\":12}".to_vec(),
            "has no `len` that is a whole number",
        ),
        (b"{\"arrays\":[{\"name\":\"a\",\"len\":0,\"x\":1}],\"data_bytes\":0}".to_vec(), "has the unknown key `x`"),
        (
            b"{\"arrays\":[{\"name\":\"a\",\"len\":0},{\"name\":\"a\",\"len\":0}],\"data_bytes\":0}".to_vec(),
            "lists the name `a` twice",
        ),
        (
            b"{\"arrays\":[{\"name\":\"a\",\"len\":1}],\"data_bytes\":16}".to_vec(),
            "`data_bytes` is 16, but the arrays' lengths add up to 8 bytes",
        ),
        (
            b"{\"arrays\":[{\"name\":\"a\",\"len\":2305843009213693952}],\"data_bytes\":0}".to_vec(),
            "array `a` has 2305843009213693952 values, which makes the data larger than any file can be",
        ),
        (
            format!(
                "{{\"arrays\":[{{\"name\":\"a\",\"len\":{n}}},{{\"name\":\"b\",\"len\":{n}}}],\"data_bytes\":0}}",
                n = 1u64 << 60
            )
            .into_bytes(),
            "array `b` has 1152921504606846976 values, which makes the data larger",
        ),
    ];
    for (header, expected) in cases {
        let bytes = assemble(FORMAT_VERSION, &header, &[1.0]);
        refused(&bytes, "bad header: ");
        let kind = refused(&bytes, expected);
        assert!(matches!(kind, ContainerErrorKind::BadHeader { .. }), "{expected}: {kind}");
    }
}

#[test]
fn huge_declared_data_is_truncation_not_allocation() {
    let n = 1u64 << 60;
    let header = format!("{{\"arrays\":[{{\"name\":\"a\",\"len\":{n}}}],\"data_bytes\":{}}}", n * 8);
    let bytes = assemble(FORMAT_VERSION, header.as_bytes(), &[1.0, 2.0]);
    let kind = refused(&bytes, &format!("truncated: {} bytes, the header describes", bytes.len()));
    let expected = bytes.len() as u128 - 16 + u128::from(n * 8);
    assert!(matches!(kind, ContainerErrorKind::Truncated { needed: Needed::Exactly(e), .. } if e == expected));
}

#[test]
fn random_mutations_never_panic_and_never_read_as_valid() {
    let valid = sample().to_bytes().unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(0x0c0a_b001);
    let mut refused_as = std::collections::BTreeMap::<&str, usize>::new();
    for _ in 0..2000 {
        let mut bytes = valid.clone();
        for _ in 0..rng.gen_range(1..=4) {
            let len = bytes.len();
            match rng.gen_range(0..7) {
                0 if len > 0 => {
                    let at = rng.gen_range(0..len);
                    bytes[at] ^= 1 << rng.gen_range(0..8);
                }
                1 if len > 0 => {
                    let at = rng.gen_range(0..len);
                    bytes[at] = rng.r#gen();
                }
                2 => {
                    let at = rng.gen_range(0..=len);
                    bytes.insert(at, rng.r#gen());
                }
                3 if len > 0 => {
                    bytes.remove(rng.gen_range(0..len));
                }
                4 => bytes.truncate(rng.gen_range(0..=len)),
                5 if len >= HEADER_AT => {
                    let field = rng.gen_range(VERSION_AT..HEADER_AT - 1);
                    bytes[field] = rng.r#gen();
                }
                _ => bytes.extend((0..rng.gen_range(1..9)).map(|_| rng.r#gen::<u8>())),
            }
        }
        if bytes == valid {
            continue;
        }
        let err = error_of(Container::from_bytes(&bytes, NAME));
        assert!(err.to_string().starts_with(NAME));
        let kind = match *err.kind {
            ContainerErrorKind::NotVocab { .. } => "not a vocabulary file",
            ContainerErrorKind::NewerVersion { .. } => "newer",
            ContainerErrorKind::UnknownVersion { .. } => "unknown version",
            ContainerErrorKind::OlderJointSpace { .. } => "older joint space",
            ContainerErrorKind::Truncated { .. } => "truncated",
            ContainerErrorKind::Corrupt { .. } => "corrupt",
            ContainerErrorKind::BadHeader { .. } => "bad header",
            ContainerErrorKind::TrailingBytes { .. } => "trailing",
            ContainerErrorKind::Read(_) | ContainerErrorKind::Write(_) | ContainerErrorKind::Invalid(_) => {
                panic!("reading bytes cannot fail with {err}")
            }
        };
        *refused_as.entry(kind).or_default() += 1;
    }
    // The mutations reach every check, not just the first.
    for kind in ["not a vocabulary file", "newer", "truncated", "corrupt", "bad header"] {
        assert!(refused_as.get(kind).copied().unwrap_or(0) > 0, "no mutation was refused as {kind}: {refused_as:?}");
    }
}
