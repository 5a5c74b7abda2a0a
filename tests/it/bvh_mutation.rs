//! Random damage to the real captures never makes the reader (or the
//! retargeter behind it) panic: every mutated file is read or refused with
//! a message naming it. Seeded, so a failure reproduces everywhere.

use crate::common;

use imitate::mocap::bvh::read_bvh_bytes;
use imitate::mocap::retarget::Retargeter;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};
use std::sync::OnceLock;

/// Cases per kind of mutation.
const CASES: u32 = 64;

struct Capture {
    name: String,
    bytes: Vec<u8>,
    /// Where `MOTION` starts: the hierarchy is everything before.
    motion_at: usize,
}

/// The real captures, read once for every test; empty when the folder is
/// absent outside CI.
fn captures() -> &'static [Capture] {
    static CAPTURES: OnceLock<Vec<Capture>> = OnceLock::new();
    CAPTURES.get_or_init(|| {
        common::real_bvh_files()
            .iter()
            .map(|path| {
                let bytes = std::fs::read(path).unwrap();
                let motion_at =
                    bytes.windows(6).position(|w| w == b"MOTION").expect("every real capture has a MOTION section");
                let name = path.file_name().unwrap().to_string_lossy().into_owned();
                Capture { name, bytes, motion_at }
            })
            .collect()
    })
}

/// A place in a file, as fractions so that it fits any file: in the
/// hierarchy, in the motion header (MOTION, Frames, Frame Time and the
/// first frame), or anywhere.
#[derive(Clone, Copy, Debug)]
enum Spot {
    Hierarchy(u32),
    MotionHeader(u32),
    Anywhere(u32),
}

impl Spot {
    fn resolve(self, c: &Capture) -> usize {
        let scale = |x: u32, len: usize| ((x as u64 * len as u64) >> 32) as usize;
        match self {
            Spot::Hierarchy(x) => scale(x, c.motion_at),
            Spot::MotionHeader(x) => {
                let end = (c.motion_at + 2000).min(c.bytes.len());
                c.motion_at + scale(x, end - c.motion_at)
            }
            Spot::Anywhere(x) => scale(x, c.bytes.len()),
        }
    }
}

fn spot() -> impl Strategy<Value = Spot> {
    prop_oneof![
        any::<u32>().prop_map(Spot::Hierarchy),
        any::<u32>().prop_map(Spot::MotionHeader),
        any::<u32>().prop_map(Spot::Anywhere),
    ]
}

#[derive(Clone, Debug)]
enum Mutation {
    DeleteRange { at: Spot, len: usize },
    DuplicateLine { at: Spot },
    SwapTokens { a: Spot, b: Spot },
    ReplaceToken { at: Spot, garbage: Vec<u8> },
    Truncate { at: Spot },
}

fn is_space(b: u8) -> bool {
    b.is_ascii_whitespace()
}

/// The whitespace-separated token at or after `pos`, as a byte range.
fn token_at(bytes: &[u8], pos: usize) -> Option<(usize, usize)> {
    let mut start = pos.min(bytes.len());
    while start > 0 && !is_space(bytes[start - 1]) {
        start -= 1;
    }
    while start < bytes.len() && is_space(bytes[start]) {
        start += 1;
    }
    if start == bytes.len() {
        return None;
    }
    let end = bytes[start..].iter().position(|&b| is_space(b)).map_or(bytes.len(), |p| start + p);
    Some((start, end))
}

fn apply(m: &Mutation, c: &Capture) -> Vec<u8> {
    let mut bytes = c.bytes.clone();
    match m {
        Mutation::DeleteRange { at, len } => {
            let start = at.resolve(c);
            let end = (start + len).min(bytes.len());
            bytes.drain(start..end);
        }
        Mutation::DuplicateLine { at } => {
            let pos = at.resolve(c);
            let start = bytes[..pos].iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1);
            let end = bytes[pos..].iter().position(|&b| b == b'\n').map_or(bytes.len(), |p| pos + p + 1);
            let line = bytes[start..end].to_vec();
            bytes.splice(end..end, line);
        }
        Mutation::SwapTokens { a, b } => {
            let (Some(x), Some(y)) = (token_at(&bytes, a.resolve(c)), token_at(&bytes, b.resolve(c))) else {
                return bytes;
            };
            let (first, second) = if x.0 <= y.0 { (x, y) } else { (y, x) };
            if first.0 == second.0 {
                return bytes;
            }
            let mut out = Vec::with_capacity(bytes.len());
            out.extend_from_slice(&bytes[..first.0]);
            out.extend_from_slice(&bytes[second.0..second.1]);
            out.extend_from_slice(&bytes[first.1..second.0]);
            out.extend_from_slice(&bytes[first.0..first.1]);
            out.extend_from_slice(&bytes[second.1..]);
            return out;
        }
        Mutation::ReplaceToken { at, garbage } => {
            if let Some((start, end)) = token_at(&bytes, at.resolve(c)) {
                bytes.splice(start..end, garbage.iter().copied());
            }
        }
        Mutation::Truncate { at } => bytes.truncate(at.resolve(c)),
    }
    bytes
}

/// Tokens that break BVH in telling ways, and random bytes.
fn garbage() -> impl Strategy<Value = Vec<u8>> {
    let telling: Vec<&'static [u8]> = vec![
        b"",
        b"nan",
        b"-inf",
        b"1.#IND",
        b"1e999",
        b"1e300",
        b"-1.7976931348623157e308",
        b"4.9e-324",
        b"0",
        b"-0",
        b"-",
        b".",
        b"{",
        b"}",
        b"}}}",
        b"{ {",
        b"ROOT",
        b"JOINT X",
        b"End Site",
        b"MOTION",
        b"Frames: -1",
        b"Frame Time: 0",
        b"CHANNELS",
        b"CHANNELS 6",
        b"99999999999999999999",
        b"0.0-7.509",
        b"\0",
        b"\n",
        b"\r\n\r\n",
        b"\xef\xbb\xbf",
        b"\xff\xfe",
        "é—🙂".as_bytes(),
    ];
    prop_oneof![
        3 => proptest::sample::select(telling).prop_map(<[u8]>::to_vec),
        1 => proptest::collection::vec(any::<u8>(), 1..24),
    ]
}

/// Reads the mutated bytes: Ok, or an error whose message names the file.
/// When reading succeeds, the values fill whole frames and retargeting
/// (when the skeleton maps) runs without panicking.
fn check(name: &str, bytes: &[u8]) -> Result<(), TestCaseError> {
    match read_bvh_bytes(bytes, name) {
        Ok(bvh) => {
            prop_assert_eq!(bvh.data.len(), bvh.frames * bvh.channel_count());
            prop_assert!(bvh.data.iter().all(|v| v.is_finite()));
            prop_assert!(bvh.frame_time_s > 0.0);
            if let Ok(retargeter) = Retargeter::new(&bvh, &Default::default()) {
                let motion = retargeter.retarget(&bvh);
                prop_assert_eq!(motion.poses.len(), bvh.frames);
            }
        }
        Err(e) => {
            let message = e.to_string();
            prop_assert!(message.starts_with(name), "{}", message);
            prop_assert!(message.len() > name.len() + 2, "{}", message);
        }
    }
    Ok(())
}

/// Runs `CASES` mutations drawn from `mutation`, each on a capture chosen
/// at random, with a fixed seed.
fn run(seed: u8, mutation: impl Strategy<Value = Mutation>) {
    let captures = captures();
    if captures.is_empty() {
        return;
    }
    let config =
        Config { cases: CASES, failure_persistence: None, rng_algorithm: RngAlgorithm::ChaCha, ..Config::default() };
    let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &[seed; 32]);
    let mut runner = TestRunner::new_with_rng(config, rng);
    let result = runner.run(&(0..captures.len(), mutation), |(i, m)| {
        let c = &captures[i];
        check(&c.name, &apply(&m, c))
    });
    if let Err(e) = result {
        panic!("{e}");
    }
}

#[test]
fn deleting_a_byte_range_never_panics() {
    let len = prop_oneof![1usize..16, 16usize..4096];
    run(1, (spot(), len).prop_map(|(at, len)| Mutation::DeleteRange { at, len }));
}

#[test]
fn duplicating_a_line_never_panics() {
    run(2, spot().prop_map(|at| Mutation::DuplicateLine { at }));
}

#[test]
fn swapping_two_tokens_never_panics() {
    run(3, (spot(), spot()).prop_map(|(a, b)| Mutation::SwapTokens { a, b }));
}

#[test]
fn replacing_a_token_by_garbage_never_panics() {
    run(4, (spot(), garbage()).prop_map(|(at, garbage)| Mutation::ReplaceToken { at, garbage }));
}

#[test]
fn truncating_never_panics() {
    run(5, spot().prop_map(|at| Mutation::Truncate { at }));
}
