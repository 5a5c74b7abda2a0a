//! Writing BVH text that Blender, MotionBuilder and other readers import:
//! tab-indented hierarchy, `End Site` blocks, one frame per line. Values
//! are written with six decimals (1e-6 degree is 2e-8 rad), the frame time
//! with the shortest digits that read back to the same f64.

use super::{Bvh, Skeleton};
use std::io::{self, Write};

/// Writes `bvh` as BVH text.
pub fn write_bvh(bvh: &Bvh, out: &mut impl Write) -> io::Result<()> {
    let skeleton = &bvh.skeleton;
    let order = preorder(skeleton);
    let mut text = String::with_capacity(4096);
    text.push_str("HIERARCHY\n");
    for &root in order.iter().filter(|&&j| skeleton.joints[j].parent.is_none()) {
        write_joint(skeleton, root, 0, &mut text);
    }
    text.push_str(&format!("MOTION\nFrames: {}\nFrame Time: {}\n", bvh.frames, bvh.frame_time_s));
    out.write_all(text.as_bytes())?;

    // Channel indices in the order the hierarchy above lists them.
    let columns: Vec<usize> = order
        .iter()
        .flat_map(|&j| {
            let joint = &skeleton.joints[j];
            joint.first_channel..joint.first_channel + joint.channels.len()
        })
        .collect();
    let mut line = Vec::with_capacity(columns.len() * 12);
    for f in 0..bvh.frames {
        let frame = bvh.frame(f);
        line.clear();
        for (k, &c) in columns.iter().enumerate() {
            if k > 0 {
                line.push(b' ');
            }
            push_fixed6(frame[c], &mut line);
        }
        line.push(b'\n');
        out.write_all(&line)?;
    }
    out.flush()
}

/// Joints in depth-first order, children in index order: the order a
/// hierarchy is written in.
fn preorder(skeleton: &Skeleton) -> Vec<usize> {
    let mut order = Vec::with_capacity(skeleton.joints.len());
    let mut stack: Vec<usize> = skeleton.roots().collect();
    stack.reverse();
    while let Some(j) = stack.pop() {
        order.push(j);
        let mut children: Vec<usize> = skeleton.children(j).collect();
        children.reverse();
        stack.extend(children);
    }
    order
}

fn write_joint(skeleton: &Skeleton, j: usize, depth: usize, text: &mut String) {
    let joint = &skeleton.joints[j];
    let indent = "\t".repeat(depth);
    let keyword = if joint.parent.is_none() { "ROOT" } else { "JOINT" };
    text.push_str(&format!("{indent}{keyword} {}\n{indent}{{\n", joint.name));
    text.push_str(&format!("{indent}\tOFFSET {}\n", fixed3(joint.offset.to_array())));
    let names: Vec<&str> = joint.channels.iter().map(|c| c.name()).collect();
    text.push_str(&format!("{indent}\tCHANNELS {} {}\n", names.len(), names.join(" ")));
    for child in skeleton.children(j) {
        write_joint(skeleton, child, depth + 1, text);
    }
    if let Some(end) = joint.end_site {
        text.push_str(&format!(
            "{indent}\tEnd Site\n{indent}\t{{\n{indent}\t\tOFFSET {}\n{indent}\t}}\n",
            fixed3(end.to_array())
        ));
    }
    text.push_str(&format!("{indent}}}\n"));
}

fn fixed3(v: [f64; 3]) -> String {
    let mut out = Vec::with_capacity(40);
    for (i, x) in v.into_iter().enumerate() {
        if i > 0 {
            out.push(b' ');
        }
        push_fixed6(x, &mut out);
    }
    String::from_utf8(out).expect("digits are ASCII")
}

/// Appends `v` with exactly six decimals. Much faster than `format!` for
/// the millions of values a long take holds; `-0.000000` is written as
/// `0.000000` so output does not depend on the sign of zero.
fn push_fixed6(v: f64, out: &mut Vec<u8>) {
    let scaled = (v * 1e6).round();
    if scaled.is_nan() || scaled.abs() >= 9.0e18 {
        // Beyond i64 (or not finite): rare enough for the general path.
        out.extend_from_slice(format!("{v:.6}").as_bytes());
        return;
    }
    let scaled = scaled as i64;
    if scaled < 0 {
        out.push(b'-');
    }
    let magnitude = scaled.unsigned_abs();
    let (whole, frac) = (magnitude / 1_000_000, magnitude % 1_000_000);
    let mut digits = [0u8; 20];
    let mut n = 0;
    let mut w = whole;
    loop {
        digits[n] = b'0' + (w % 10) as u8;
        n += 1;
        w /= 10;
        if w == 0 {
            break;
        }
    }
    out.extend(digits[..n].iter().rev());
    out.push(b'.');
    let mut f = frac;
    let mut decimals = [0u8; 6];
    for d in decimals.iter_mut().rev() {
        *d = b'0' + (f % 10) as u8;
        f /= 10;
    }
    out.extend_from_slice(&decimals);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixed(v: f64) -> String {
        let mut out = Vec::new();
        push_fixed6(v, &mut out);
        String::from_utf8(out).unwrap()
    }

    #[test]
    fn fixed6_matches_standard_formatting_and_drops_negative_zero() {
        for v in [0.0, 1.0, -1.5, 179.999999, 123456.000001, -0.0000004, 1e-7, 98765.4321] {
            let expected = format!("{v:.6}");
            let expected = if expected == "-0.000000" { "0.000000".to_string() } else { expected };
            assert_eq!(fixed(v), expected, "{v}");
        }
        assert_eq!(fixed(-0.0), "0.000000");
        assert_eq!(fixed(1e30), format!("{:.6}", 1e30));
    }
}
