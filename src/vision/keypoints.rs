//! 2-D keypoints from a detector the user already has, read as a second
//! observation of the person (docs/formats.md, "Keypoints"): MediaPipe
//! Pose's landmarks (the CSV or JSON `scripts/keypoints.py` writes),
//! OpenPose's per-frame JSON (BODY_25 or its 18-point COCO model) and
//! COCO-17 results JSON. Every layout is reduced to the [`Site`]s the
//! tracker's skeleton has, so the likelihood never sees which detector
//! wrote them.

use serde_json::Value;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// A body point every layout names and the tracker's skeleton has.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Site {
    Nose,
    Neck,
    LeftShoulder,
    RightShoulder,
    LeftElbow,
    RightElbow,
    LeftWrist,
    RightWrist,
    MidHip,
    LeftHip,
    RightHip,
    LeftKnee,
    RightKnee,
    LeftAnkle,
    RightAnkle,
}

impl Site {
    pub const ALL: [Site; 15] = [
        Site::Nose,
        Site::Neck,
        Site::LeftShoulder,
        Site::RightShoulder,
        Site::LeftElbow,
        Site::RightElbow,
        Site::LeftWrist,
        Site::RightWrist,
        Site::MidHip,
        Site::LeftHip,
        Site::RightHip,
        Site::LeftKnee,
        Site::RightKnee,
        Site::LeftAnkle,
        Site::RightAnkle,
    ];

    /// The site a layout's joint `name` is (MediaPipe's, OpenPose's and
    /// COCO's names, in any case, `_` or ` ` or none between words); `None`
    /// for points the skeleton has no joint for (eyes, fingers, heels).
    pub fn named(name: &str) -> Option<Site> {
        let key: String = name.chars().filter(|c| c.is_ascii_alphanumeric()).collect::<String>().to_ascii_lowercase();
        let site = match key.as_str() {
            "nose" => Site::Nose,
            "neck" => Site::Neck,
            "leftshoulder" | "lshoulder" => Site::LeftShoulder,
            "rightshoulder" | "rshoulder" => Site::RightShoulder,
            "leftelbow" | "lelbow" => Site::LeftElbow,
            "rightelbow" | "relbow" => Site::RightElbow,
            "leftwrist" | "lwrist" => Site::LeftWrist,
            "rightwrist" | "rwrist" => Site::RightWrist,
            "midhip" | "pelvis" => Site::MidHip,
            "lefthip" | "lhip" => Site::LeftHip,
            "righthip" | "rhip" => Site::RightHip,
            "leftknee" | "lknee" => Site::LeftKnee,
            "rightknee" | "rknee" => Site::RightKnee,
            "leftankle" | "lankle" => Site::LeftAnkle,
            "rightankle" | "rankle" => Site::RightAnkle,
            _ => return None,
        };
        Some(site)
    }

    /// Its place in [`SitePoints`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// Its name in snake case (`left_shoulder`), which [`Site::named`] reads.
    pub fn name(self) -> &'static str {
        const NAMES: [&str; 15] = [
            "nose",
            "neck",
            "left_shoulder",
            "right_shoulder",
            "left_elbow",
            "right_elbow",
            "left_wrist",
            "right_wrist",
            "mid_hip",
            "left_hip",
            "right_hip",
            "left_knee",
            "right_knee",
            "left_ankle",
            "right_ankle",
        ];
        NAMES[self.index()]
    }
}

/// A layout a detector writes its points in, by their order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// MediaPipe Pose's 33 landmarks.
    MediaPipe,
    /// OpenPose's BODY_25.
    Body25,
    /// OpenPose's 18-point COCO model (COCO's 17 and the neck).
    OpenPoseCoco18,
    /// COCO's 17 keypoints.
    Coco17,
}

impl Layout {
    pub fn name(self) -> &'static str {
        match self {
            Layout::MediaPipe => "mediapipe",
            Layout::Body25 => "body25",
            Layout::OpenPoseCoco18 => "openpose-coco18",
            Layout::Coco17 => "coco17",
        }
    }

    /// The sites of the layout's points, in its order (`None` for points
    /// the skeleton has no joint for).
    pub fn sites(self) -> Vec<Option<Site>> {
        use Site::*;
        let coco17 = [
            Some(Nose),
            None,
            None,
            None,
            None,
            Some(LeftShoulder),
            Some(RightShoulder),
            Some(LeftElbow),
            Some(RightElbow),
            Some(LeftWrist),
            Some(RightWrist),
            Some(LeftHip),
            Some(RightHip),
            Some(LeftKnee),
            Some(RightKnee),
            Some(LeftAnkle),
            Some(RightAnkle),
        ];
        match self {
            Layout::Coco17 => coco17.to_vec(),
            Layout::MediaPipe => {
                let mut sites = vec![None; 33];
                sites[0] = Some(Nose);
                let pairs = [(11, LeftShoulder), (12, RightShoulder), (13, LeftElbow), (14, RightElbow)];
                let more = [(15, LeftWrist), (16, RightWrist), (23, LeftHip), (24, RightHip)];
                let legs = [(25, LeftKnee), (26, RightKnee), (27, LeftAnkle), (28, RightAnkle)];
                for (i, s) in pairs.into_iter().chain(more).chain(legs) {
                    sites[i] = Some(s);
                }
                sites
            }
            // OpenPose's two layouts share their order but for BODY_25's
            // mid-hip between the arms and the legs.
            Layout::Body25 | Layout::OpenPoseCoco18 => {
                let arms = [Nose, Neck, RightShoulder, RightElbow, RightWrist, LeftShoulder, LeftElbow, LeftWrist];
                let legs = [RightHip, RightKnee, RightAnkle, LeftHip, LeftKnee, LeftAnkle];
                let middle: &[Site] = if self == Layout::Body25 { &[MidHip] } else { &[] };
                let count = if self == Layout::Body25 { 25 } else { 18 };
                let mut sites: Vec<Option<Site>> = arms.iter().chain(middle).chain(&legs).copied().map(Some).collect();
                sites.resize(count, None);
                sites
            }
        }
    }

    /// The layout of `count` points in a flat OpenPose or COCO array.
    fn of_count(count: usize) -> Option<Layout> {
        match count {
            25 => Some(Layout::Body25),
            18 => Some(Layout::OpenPoseCoco18),
            17 => Some(Layout::Coco17),
            33 => Some(Layout::MediaPipe),
            _ => None,
        }
    }
}

/// One point: pixels from the frame's top left, and the detector's
/// confidence in [0, 1].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Keypoint {
    pub x: f64,
    pub y: f64,
    pub confidence: f64,
}

/// One frame's points by [`Site`]; all `None` where nobody was found.
pub type SitePoints = [Option<Keypoint>; 15];

/// A file's keypoints, frame by frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Keypoints {
    /// The file (or folder, for OpenPose) they were read from.
    pub path: PathBuf,
    /// The layout the file named, when it named one.
    pub layout: Option<Layout>,
    /// The frame size the file states, when it states one.
    pub size: Option<(usize, usize)>,
    pub frames: Vec<SitePoints>,
    /// Points dropped on reading: coordinates not finite, or a
    /// confidence of zero.
    pub dropped: usize,
    /// Whether every frame is listed (JSON documents, OpenPose folders);
    /// a CSV or COCO results may leave out the frames after the last
    /// detection.
    pub complete: bool,
}

/// Why a keypoints file cannot be used.
#[derive(Debug, Error)]
pub enum KeypointsError {
    #[error("{path}: cannot read: {source}")]
    Read { path: PathBuf, source: std::io::Error },
    #[error("{path}: not a keypoints file: {reason}")]
    Format { path: PathBuf, reason: String },
    #[error("{path}: keypoints of {found} frames, and the video has {expected}: keypoints of another video?")]
    FrameCount { path: PathBuf, found: usize, expected: usize },
    #[error("{path}: keypoints of {width}×{height} frames, and the video's are {frame_width}×{frame_height}")]
    Size { path: PathBuf, width: usize, height: usize, frame_width: usize, frame_height: usize },
    #[error("{path}: no frame has a usable keypoint")]
    Empty { path: PathBuf },
}

impl Keypoints {
    /// Reads `path`: a `.csv` (`frame,joint,x,y,confidence`), a `.json`
    /// (the MediaPipe document `scripts/keypoints.py` writes, or COCO
    /// results), or a folder of OpenPose `*_keypoints.json` files.
    pub fn read(path: &Path) -> Result<Keypoints, KeypointsError> {
        let format = |reason: String| KeypointsError::Format { path: path.to_path_buf(), reason };
        let keypoints = if path.is_dir() {
            read_openpose(path)?
        } else {
            let text = std::fs::read_to_string(path)
                .map_err(|source| KeypointsError::Read { path: path.to_path_buf(), source })?;
            let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
            match extension.as_deref() {
                Some("csv") => read_csv(path, &text).map_err(format)?,
                Some("json") => read_json(path, &text).map_err(format)?,
                _ => {
                    return Err(format(
                        "the name must end in .csv or .json, or name a folder of OpenPose files".into(),
                    ));
                }
            }
        };
        if keypoints.frames.iter().all(|f| f.iter().all(Option::is_none)) {
            return Err(KeypointsError::Empty { path: path.to_path_buf() });
        }
        Ok(keypoints)
    }

    /// Checks the keypoints against frames of `width` × `height` (where
    /// the file states a size) and drops the points outside them; returns
    /// how many.
    pub fn fit_to(&mut self, width: usize, height: usize) -> Result<usize, KeypointsError> {
        if let Some((w, h)) = self.size
            && (w, h) != (width, height)
        {
            return Err(KeypointsError::Size {
                path: self.path.clone(),
                width: w,
                height: h,
                frame_width: width,
                frame_height: height,
            });
        }
        let inside = |k: &Keypoint| k.x >= 0.0 && k.y >= 0.0 && k.x <= width as f64 && k.y <= height as f64;
        let mut outside = 0;
        for point in self.frames.iter_mut().flatten() {
            if point.as_ref().is_some_and(|k| !inside(k)) {
                *point = None;
                outside += 1;
            }
        }
        Ok(outside)
    }

    /// Moves every point from frames of `from` (width, height) to frames
    /// of `to`, as the tracker's working size reduces them.
    pub fn rescale(&mut self, from: (usize, usize), to: (usize, usize)) {
        let (sx, sy) = (to.0 as f64 / from.0 as f64, to.1 as f64 / from.1 as f64);
        for point in self.frames.iter_mut().flatten().flatten() {
            (point.x, point.y) = (point.x * sx, point.y * sy);
        }
    }

    /// Refuses keypoints of another number of frames than the video's
    /// `frames` (where the file may leave frames out, of more).
    pub fn check_frames(&self, frames: usize) -> Result<(), KeypointsError> {
        if self.frames.len() > frames || (self.complete && self.frames.len() != frames) {
            return Err(KeypointsError::FrameCount {
                path: self.path.clone(),
                found: self.frames.len(),
                expected: frames,
            });
        }
        Ok(())
    }
}

/// The torso's length in `points`, pixels: mid-shoulder to mid-hip
/// (either side's point standing in for a missing other), or the neck and
/// mid-hip of OpenPose's layouts; `None` when not seen.
pub fn torso_px(points: &SitePoints) -> Option<f64> {
    let at = |s: Site| points[s.index()].map(|k| (k.x, k.y));
    let middle = |a: Site, b: Site| match (at(a), at(b)) {
        (Some(p), Some(q)) => Some(((p.0 + q.0) / 2.0, (p.1 + q.1) / 2.0)),
        (p, q) => p.or(q),
    };
    let top = middle(Site::LeftShoulder, Site::RightShoulder).or_else(|| at(Site::Neck))?;
    let bottom = middle(Site::LeftHip, Site::RightHip).or_else(|| at(Site::MidHip))?;
    let length = (top.0 - bottom.0).hypot(top.1 - bottom.1);
    (length > 0.0).then_some(length)
}

/// A point worth keeping: finite, with some confidence (clamped to 1).
fn usable(x: f64, y: f64, confidence: f64) -> Option<Keypoint> {
    (x.is_finite() && y.is_finite() && confidence.is_finite() && confidence > 0.0).then_some(Keypoint {
        x,
        y,
        confidence: confidence.min(1.0),
    })
}

/// Sets `site`'s point in `frame`, counting a point that is not usable.
fn put(frame: &mut SitePoints, site: Option<Site>, x: f64, y: f64, confidence: f64, dropped: &mut usize) {
    let Some(site) = site else { return };
    match usable(x, y, confidence) {
        Some(k) => frame[site.index()] = Some(k),
        None => *dropped += 1,
    }
}

fn read_csv(path: &Path, text: &str) -> Result<Keypoints, String> {
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
    let (_, header) = lines.next().ok_or("the file is empty")?;
    let columns: Vec<&str> = header.split(',').map(str::trim).collect();
    let at = |name: &str| columns.iter().position(|c| *c == name).ok_or(format!("no `{name}` column"));
    let [frame_at, joint_at, x_at, y_at, c_at] = ["frame", "joint", "x", "y", "confidence"].map(at);
    let (frame_at, joint_at, x_at, y_at, c_at) = (frame_at?, joint_at?, x_at?, y_at?, c_at?);
    let mut frames: Vec<SitePoints> = Vec::new();
    let mut dropped = 0;
    for (i, line) in lines {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        let cell = |k: usize| {
            cells.get(k).copied().ok_or(format!("line {}: {} cells, {} expected", i + 1, cells.len(), columns.len()))
        };
        let frame: usize = cell(frame_at)?.parse().map_err(|_| format!("line {}: the frame is not a number", i + 1))?;
        if frame >= frames.len() {
            frames.resize(frame + 1, [None; 15]);
        }
        // An empty coordinate is a point the detector did not find.
        let number = |k: usize| -> Result<f64, String> {
            let c = cell(k)?;
            if c.is_empty() {
                Ok(f64::NAN)
            } else {
                c.parse().map_err(|_| format!("line {}: `{c}` is not a number", i + 1))
            }
        };
        let (x, y, confidence) = (number(x_at)?, number(y_at)?, number(c_at)?);
        let absent = cell(x_at)?.is_empty() && cell(y_at)?.is_empty();
        let site = Site::named(cell(joint_at)?);
        if absent {
            continue;
        }
        put(&mut frames[frame], site, x, y, confidence, &mut dropped);
    }
    Ok(Keypoints { path: path.to_path_buf(), layout: None, size: None, frames, dropped, complete: false })
}

fn read_json(path: &Path, text: &str) -> Result<Keypoints, String> {
    let document: Value = serde_json::from_str(text).map_err(|e| format!("not JSON: {e}"))?;
    match &document {
        Value::Array(detections) => read_coco(path, detections),
        Value::Object(fields) if fields.contains_key("frames") => read_document(path, &document),
        Value::Object(fields) if fields.contains_key("people") => {
            Err("one OpenPose frame: give the folder of every frame's file".into())
        }
        _ => Err("neither a keypoints document (`frames`) nor COCO results (a list of detections)".into()),
    }
}

/// The document `scripts/keypoints.py` writes: `joints` names the points
/// of each frame's `[x, y, confidence]` list; a frame is `null` where
/// nobody was found.
fn read_document(path: &Path, document: &Value) -> Result<Keypoints, String> {
    let names: Vec<Option<Site>> = match document.get("joints").and_then(Value::as_array) {
        Some(names) => names.iter().map(|n| n.as_str().and_then(Site::named)).collect(),
        None => Layout::MediaPipe.sites(),
    };
    let layout = match document.get("layout").and_then(Value::as_str) {
        Some("mediapipe") => Some(Layout::MediaPipe),
        _ => None,
    };
    let dimension = |key: &str| document.get(key).and_then(Value::as_u64).map(|v| v as usize);
    let size = dimension("width").zip(dimension("height"));
    let list = document["frames"].as_array().ok_or("`frames` is not a list")?;
    let mut frames = Vec::with_capacity(list.len());
    let mut dropped = 0;
    for (k, frame) in list.iter().enumerate() {
        let mut points = [None; 15];
        if let Some(list) = frame.as_array() {
            if list.len() != names.len() {
                return Err(format!("frame {k} has {} points, `joints` names {}", list.len(), names.len()));
            }
            for (point, site) in list.iter().zip(&names) {
                let v = |i: usize| point.get(i).and_then(Value::as_f64).unwrap_or(f64::NAN);
                put(&mut points, *site, v(0), v(1), v(2), &mut dropped);
            }
        } else if !frame.is_null() {
            return Err(format!("frame {k} is neither a list of points nor null"));
        }
        frames.push(points);
    }
    Ok(Keypoints { path: path.to_path_buf(), layout, size, frames, dropped, complete: true })
}

/// COCO results: `{"image_id": frame, "keypoints": [x, y, c, …]}` per
/// detection; the most confident detection of each frame is the person.
fn read_coco(path: &Path, detections: &[Value]) -> Result<Keypoints, String> {
    let mut best: Vec<Option<(f64, &[Value])>> = Vec::new();
    for (i, d) in detections.iter().enumerate() {
        let frame = d.get("image_id").and_then(Value::as_u64).ok_or(format!("detection {i} has no `image_id`"))?;
        let flat = d.get("keypoints").and_then(Value::as_array).ok_or(format!("detection {i} has no `keypoints`"))?;
        if flat.len() != 51 {
            return Err(format!("detection {i} has {} keypoint numbers, COCO-17 has 51", flat.len()));
        }
        let score = d.get("score").and_then(Value::as_f64).unwrap_or(1.0);
        let frame = frame as usize;
        if frame >= best.len() {
            best.resize(frame + 1, None);
        }
        if best[frame].is_none_or(|(s, _)| score > s) {
            best[frame] = Some((score, flat));
        }
    }
    let sites = Layout::Coco17.sites();
    let mut dropped = 0;
    let frames = best
        .into_iter()
        .map(|b| {
            let mut points = [None; 15];
            if let Some((_, flat)) = b {
                flatten_into(flat, &sites, &mut points, &mut dropped);
            }
            points
        })
        .collect();
    Ok(Keypoints {
        path: path.to_path_buf(),
        layout: Some(Layout::Coco17),
        size: None,
        frames,
        dropped,
        complete: false,
    })
}

/// A flat `[x, y, c, …]` array into sites; (0, 0, 0) is OpenPose's "not found".
fn flatten_into(flat: &[Value], sites: &[Option<Site>], points: &mut SitePoints, dropped: &mut usize) {
    for (triple, site) in flat.chunks_exact(3).zip(sites) {
        let v = |i: usize| triple[i].as_f64().unwrap_or(f64::NAN);
        if v(0) == 0.0 && v(1) == 0.0 && v(2) == 0.0 {
            continue;
        }
        put(points, *site, v(0), v(1), v(2), dropped);
    }
}

/// A folder of OpenPose's `*_keypoints.json`, one per frame in name
/// order; of several people, the one with the most summed confidence.
fn read_openpose(folder: &Path) -> Result<Keypoints, KeypointsError> {
    let read = |source| KeypointsError::Read { path: folder.to_path_buf(), source };
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder)
        .map_err(read)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.file_name().and_then(|n| n.to_str()).is_some_and(|n| n.ends_with("_keypoints.json")))
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(KeypointsError::Format {
            path: folder.to_path_buf(),
            reason: "a folder, and no OpenPose `*_keypoints.json` file in it".into(),
        });
    }
    let (mut frames, mut dropped, mut layout) = (Vec::with_capacity(files.len()), 0, None);
    for file in &files {
        let format = |reason: String| KeypointsError::Format { path: file.clone(), reason };
        let text =
            std::fs::read_to_string(file).map_err(|source| KeypointsError::Read { path: file.clone(), source })?;
        let document: Value = serde_json::from_str(&text).map_err(|e| format(format!("not JSON: {e}")))?;
        let people =
            document.get("people").and_then(Value::as_array).ok_or_else(|| format("no `people` list".into()))?;
        let mut points = [None; 15];
        let confidence = |flat: &[Value]| flat.chunks_exact(3).filter_map(|t| t[2].as_f64()).sum::<f64>();
        let chosen = people
            .iter()
            .filter_map(|p| p.get("pose_keypoints_2d").and_then(Value::as_array))
            .max_by(|a, b| confidence(a).total_cmp(&confidence(b)));
        if let Some(flat) = chosen {
            let found = Layout::of_count(flat.len() / 3).filter(|_| flat.len() % 3 == 0).ok_or_else(|| {
                format(format!("{} numbers in `pose_keypoints_2d`: neither BODY_25 nor COCO", flat.len()))
            })?;
            layout.get_or_insert(found);
            flatten_into(flat, &found.sites(), &mut points, &mut dropped);
        }
        frames.push(points);
    }
    Ok(Keypoints { path: folder.to_path_buf(), layout, size: None, frames, dropped, complete: true })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn every_site_is_read_back_from_its_name() {
        for site in Site::ALL {
            assert_eq!(Site::named(site.name()), Some(site));
        }
    }

    #[test]
    fn every_layout_names_the_same_sites() {
        for layout in [Layout::MediaPipe, Layout::Body25, Layout::OpenPoseCoco18, Layout::Coco17] {
            let sites = layout.sites();
            assert_eq!(Layout::of_count(sites.len()), Some(layout), "{}", layout.name());
            for s in [Site::LeftShoulder, Site::RightWrist, Site::LeftHip, Site::RightAnkle, Site::Nose] {
                assert_eq!(sites.iter().filter(|x| **x == Some(s)).count(), 1, "{}: {s:?}", layout.name());
            }
        }
        assert_eq!(Site::named("LShoulder"), Some(Site::LeftShoulder));
        assert_eq!(Site::named("right_wrist"), Some(Site::RightWrist));
        assert_eq!(Site::named("left_eye"), None);
    }

    #[test]
    fn csv_json_coco_and_openpose_read_alike() {
        let dir = tempfile::tempdir().unwrap();
        let csv = write(
            dir.path(),
            "k.csv",
            "frame,joint,x,y,confidence\n0,left_shoulder,10,20,0.9\n0,left_eye,1,1,1\n1,left_shoulder,,,0\n1,right_wrist,nan,3,1\n",
        );
        let k = Keypoints::read(&csv).unwrap();
        assert_eq!(k.frames.len(), 2);
        assert_eq!(k.frames[0][Site::LeftShoulder.index()], Some(Keypoint { x: 10.0, y: 20.0, confidence: 0.9 }));
        assert!(k.frames[1].iter().all(Option::is_none));
        assert_eq!(k.dropped, 1, "the NaN wrist");

        let mut points = vec![[0.0, 0.0, 0.0]; 33];
        points[11] = [10.0, 20.0, 0.9];
        let doc = serde_json::json!({"layout": "mediapipe", "width": 64, "height": 48, "frames": [points, null]});
        let json = write(dir.path(), "k.json", &doc.to_string());
        let j = Keypoints::read(&json).unwrap();
        assert_eq!((j.frames.clone(), j.size), (k.frames.clone(), Some((64, 48))));

        let mut flat = vec![0.0; 51];
        flat[15..18].copy_from_slice(&[10.0, 20.0, 0.9]);
        let coco = serde_json::json!([{"image_id": 0, "keypoints": flat, "score": 0.8},
            {"image_id": 0, "keypoints": vec![5.0; 51], "score": 0.1}, {"image_id": 1, "keypoints": vec![0.0; 51]}]);
        let c = Keypoints::read(&write(dir.path(), "c.json", &coco.to_string())).unwrap();
        assert_eq!(c.frames, k.frames);

        let folder = dir.path().join("openpose");
        std::fs::create_dir(&folder).unwrap();
        let mut body25 = vec![0.0; 75];
        body25[15..18].copy_from_slice(&[10.0, 20.0, 0.9]);
        write(
            &folder,
            "clip_000000000000_keypoints.json",
            &serde_json::json!({"people": [{"pose_keypoints_2d": body25}]}).to_string(),
        );
        write(&folder, "clip_000000000001_keypoints.json", r#"{"people": []}"#);
        let o = Keypoints::read(&folder).unwrap();
        assert_eq!((o.frames, o.layout), (k.frames, Some(Layout::Body25)));
    }

    #[test]
    fn another_video_s_keypoints_and_broken_files_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let csv =
            write(dir.path(), "k.csv", "frame,joint,x,y,confidence\n0,left_wrist,10,20,1\n2,left_wrist,70,20,1\n");
        let mut k = Keypoints::read(&csv).unwrap();
        let e = k.check_frames(2).unwrap_err().to_string();
        assert!(e.contains("k.csv") && e.contains("3 frames") && e.contains("2"), "{e}");
        k.check_frames(5).expect("frames after the last detection may be left out of a CSV");
        assert_eq!(k.fit_to(64, 48).unwrap(), 1, "x = 70 is outside 64 columns");
        for (name, text, says) in [
            ("a.csv", "frame,x,y\n", "no `joint` column"),
            ("b.csv", "frame,joint,x,y,confidence\n0,left_wrist,ten,2,1\n", "`ten` is not a number"),
            ("c.json", "{", "not JSON"),
            ("d.json", r#"{"people": []}"#, "folder"),
            ("e.json", r#"[{"image_id": 0, "keypoints": [1, 2]}]"#, "51"),
            ("f.csv", "frame,joint,x,y,confidence\n0,left_wrist,,,0\n", "no frame has a usable keypoint"),
            ("g.txt", "", ".csv or .json"),
        ] {
            let e = Keypoints::read(&write(dir.path(), name, text)).unwrap_err().to_string();
            assert!(e.contains(name) && e.contains(says), "{name}: {e}");
        }
    }
}
