//! Mapping any skeleton onto the canonical body without a mapping file: a
//! corpus of renamings made here (every naming scheme, with shuffled
//! joints, twist and finger joints, no neck, bind orientations, Z up in
//! centimeters), and every real file in `../shared/mocap/`, by name and
//! with its names taken away.

use crate::common;
#[path = "../common/skeletons.rs"]
mod skeletons;

use imitate::mocap::body::Joint;
use imitate::mocap::bvh::{Bvh, read_bvh};
use imitate::mocap::fidelity::DirectionErrors;
use imitate::mocap::fk::Kinematics;
use imitate::mocap::mapping::{Landmark, Mapping, map_skeleton};
use imitate::mocap::retarget::{RetargetOptions, Retargeter};
use skeletons::{Variation, generate, templates};
use std::path::PathBuf;

fn map(bvh: &Bvh) -> Mapping {
    map_skeleton(bvh, &Kinematics::new(bvh), None).expect("no mapping file, so no file error")
}

fn variations() -> Vec<(&'static str, Variation)> {
    let plain = Variation::default();
    vec![
        ("plain", plain),
        ("shuffled", Variation { shuffled: true, seed: 3, ..plain }),
        ("twist and finger joints", Variation { twist: true, fingers: true, ..plain }),
        ("no neck", Variation { no_neck: true, ..plain }),
        ("bind orientations", Variation { bind_frames: true, seed: 5, ..plain }),
        ("Z up, centimeters", Variation { z_up_cm: true, ..plain }),
        (
            "all at once",
            Variation {
                shuffled: true,
                twist: true,
                fingers: true,
                no_neck: true,
                bind_frames: true,
                z_up_cm: true,
                seed: 9,
            },
        ),
    ]
}

#[test]
fn every_scheme_and_variation_of_the_renaming_corpus_maps_to_the_right_joints() {
    let motion = skeletons::motion();
    let mut cases = 0;
    let mut failures = Vec::new();
    let mut direction_means = Vec::new();
    for template in templates() {
        for (label, variation) in variations() {
            cases += 1;
            let generated = generate(&template, variation, &motion);
            let bvh = &generated.bvh;
            let mapping = map(bvh);
            let name_of = |j: Joint| mapping.get(Landmark::Joint(j)).map(|p| bvh.skeleton.joints[p.joint].name.clone());
            for joint in Joint::ALL {
                let allowed: Vec<&str> =
                    generated.truth.iter().filter(|t| t.joint == joint).map(|t| t.name.as_str()).collect();
                let found = name_of(joint);
                if !found.as_deref().is_some_and(|f| allowed.contains(&f)) {
                    failures.push(format!(
                        "{} / {label}: {} ← {found:?}, expected {allowed:?}",
                        template.scheme,
                        joint.name()
                    ));
                }
            }
            let retargeter = match Retargeter::new(bvh, &RetargetOptions::default()) {
                Ok(r) => r,
                Err(e) => {
                    failures.push(format!("{} / {label}: {e}", template.scheme));
                    continue;
                }
            };
            let retargeted = retargeter.retarget(bvh);
            let errors = DirectionErrors::measure(bvh, &retargeter, &retargeted);
            direction_means.push(errors.mean_deg);
            if errors.mean_deg > 2.0 {
                failures.push(format!(
                    "{} / {label}: limb directions {:.2}° off on average",
                    template.scheme, errors.mean_deg
                ));
            }
        }
    }
    let mean = direction_means.iter().sum::<f64>() / direction_means.len().max(1) as f64;
    eprintln!(
        "{cases} skeletons: {} mapped every joint right; limb directions {mean:.3}° off on average, {:.3}° in the worst",
        cases - failures.len().min(cases),
        direction_means.iter().copied().fold(0.0, f64::max)
    );
    assert!(failures.is_empty(), "{} of {cases} cases wrong:\n{}", failures.len(), failures.join("\n"));
}

/// Every `.bvh` file of one of the shared corpora.
fn shared(corpus: &str) -> Vec<PathBuf> {
    let Some(dir) = common::shared_mocap_dir(corpus) else {
        return Vec::new();
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_file_of_the_shared_corpora_maps_without_a_mapping_file() {
    for corpus in ["real", "bandai", "m21"] {
        let files = shared(corpus);
        for path in &files {
            let bvh = read_bvh(path).unwrap();
            let mapping = map(&bvh);
            assert!(
                mapping.missing_required().is_empty(),
                "{}: {:?} missing",
                path.display(),
                mapping.missing_required()
            );
            // The legs are the last six canonical joints.
            for &leg in &Joint::ALL[Joint::LeftHip.index()..] {
                assert!(mapping.get(Landmark::Joint(leg)).is_some(), "{}: no {}", path.display(), leg.name());
            }
        }
        eprintln!("{corpus}: {} files mapped", files.len());
    }
}

/// The joints on the way from `top` down to `bottom`, both included.
fn chain(bvh: &Bvh, top: usize, bottom: usize) -> Vec<usize> {
    let mut path = vec![bottom];
    while *path.last().unwrap() != top {
        let at = *path.last().unwrap();
        path.push(bvh.skeleton.joints[at].parent.expect("top is an ancestor"));
    }
    path
}

#[test]
fn the_structure_alone_maps_each_real_skeleton_as_its_names_do() {
    // One file of each skeleton: names replaced by numbers, so only the
    // hierarchy, the bones and the motion are left to go by.
    let Some(real) = common::shared_mocap_dir("real") else {
        return;
    };
    let files: Vec<PathBuf> = ["boxing.bvh", "dab.bvh", "jesse_dance.bvh", "jumping_jacks.bvh"]
        .iter()
        .map(|f| real.join(f))
        .chain(shared("bandai").into_iter().take(1))
        .chain(shared("m21").into_iter().take(1))
        .collect();
    for path in files {
        let bvh = read_bvh(&path).unwrap();
        let named = map(&bvh);
        let mut anonymous = bvh.clone();
        for (i, joint) in anonymous.skeleton.joints.iter_mut().enumerate() {
            joint.name = format!("j{i}");
        }
        let found = map(&anonymous);
        assert_eq!(found.scheme, "structure", "{}", path.display());
        for joint in Joint::ALL {
            let (a, b) = (named.get(Landmark::Joint(joint)).unwrap(), found.get(Landmark::Joint(joint)).unwrap());
            let name = |p: imitate::mocap::mapping::SourcePoint| bvh.skeleton.joints[p.joint].name.clone();
            match joint {
                // Any joint of the spine's chain serves; the neck is the
                // first joint above the chest either way.
                Joint::Spine => {
                    let (pelvis, chest) = (
                        named.get(Landmark::Joint(Joint::Pelvis)).unwrap(),
                        named.get(Landmark::Joint(Joint::Chest)).unwrap(),
                    );
                    assert!(
                        chain(&bvh, pelvis.joint, chest.joint).contains(&b.joint),
                        "{}: spine {}",
                        path.display(),
                        name(b)
                    );
                }
                Joint::Neck => {
                    let head = named.get(Landmark::Joint(Joint::Head)).unwrap();
                    let chest = named.get(Landmark::Joint(Joint::Chest)).unwrap();
                    assert!(
                        chain(&bvh, chest.joint, head.joint).contains(&b.joint),
                        "{}: neck {}",
                        path.display(),
                        name(b)
                    );
                }
                _ => assert_eq!(
                    a,
                    b,
                    "{}: {} is {} by name, {} by structure",
                    path.display(),
                    joint.name(),
                    name(a),
                    name(b)
                ),
            }
        }
    }
}
