//! `imitate eval`: the paper's trials, run end to end, as a report.

mod imitation;
mod mocap;
mod person;
mod video;

use super::{Global, Outcome, UsageError, refuse_nonempty};
use anyhow::Context;
use imitate::fsutil::write_dir_atomic;
use imitate::mocap::retarget::RetargetOptions;
use imitate::mocap::synth::{Activity, SynthOptions, files};
use imitate::params::Params;
use imitate::report::eval::{Measure, Picture, Provenance, RunScore, Setting, Trial, eval_report};
use imitate::report::figures;
use imitate::report::filmstrip::{filmstrip, pick_frames};
use imitate::report::metrics::{SETTLE_S, Track, score};
use imitate::report::read_track;
use imitate::report::run::Run;
use imitate::report::write::{silhouettes, tracked_camera};
use imitate::track::clip::{Baseline, CameraChoice, ClipOptions, track_clip_with};
use imitate::track::filter::FilterParams;
use imitate::vision::camera::{Camera, Preset};
use imitate::vision::figure::Build;
use imitate::vision::filming::{DEFAULT_SIZE, Filming, film};
use imitate::vocab::cluster::ClusterParams;
use imitate::vocab::learn::{self, Built, Takes, read_take};
use imitate::vocab::pipeline::BuildParams;
use imitate::vocab::vocabulary::Vocabulary;
use indicatif::ProgressBar;
use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Run the paper's trials end to end and write an evaluation report:
/// builds a vocabulary of the four paper activities from synthetic takes
/// (or takes --vocab), renders held-out sequences, tracks and scores them,
/// and writes DIR/index.html (self-contained), each trial's table as CSV
/// and chart as PNG and SVG, filmstrips, metrics.json and timing.json (see
/// docs/formats.md).
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The report's folder (refused if it holds something, unless --force).
    #[arg(short, long, value_name = "DIR")]
    pub output: PathBuf,
    /// Track with this vocabulary instead of building one. It must hold
    /// at least two primitives.
    #[arg(long, value_name = "FILE.vocab")]
    pub vocab: Option<PathBuf>,
    /// Fewer seeds and settings: a look in under 3 minutes.
    #[arg(long)]
    pub quick: bool,
    /// Seed of the synthetic motion and of the trackers; the same seed
    /// gives the same report (but its timing).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Real captures for the real-motion trial (skipped when absent).
    #[arg(long, value_name = "DIR", default_value = "../shared/mocap/real")]
    pub real: PathBuf,
    /// Real motion capture corpora for the real-capture tables and the
    /// held-out-style trial: every subfolder holding BVH takes and a
    /// labels.csv (skipped when absent).
    #[arg(long, value_name = "DIR", default_value = "../shared/mocap")]
    pub mocap: PathBuf,
    /// Real clips for the real-video table: a folder of videos and a
    /// labels.csv (`file,activity,camera,…`), tracked with a vocabulary
    /// learned from the corpora of --mocap (skipped when not given).
    #[arg(long, value_name = "DIR")]
    pub real_video: Option<PathBuf>,
    /// MediaPipe Pose's masks and landmarks of the --real-video clips, as
    /// `bash scripts/video-reference.sh DIR` writes them (NAME/keypoints.csv
    /// and NAME/masks/ per clip): adds the silhouettes' IoU and the PCK
    /// columns.
    #[arg(long, value_name = "DIR", requires = "real_video")]
    pub video_reference: Option<PathBuf>,
    /// Keep the trials' videos and runs here [default: a temporary folder,
    /// removed afterwards].
    #[arg(long, value_name = "DIR")]
    pub work: Option<PathBuf>,
    /// Replace the output folder if it exists.
    #[arg(long)]
    pub force: bool,
}

/// What the full run and `--quick` each try.
struct Plan {
    seeds: Vec<u64>,
    particles: Vec<usize>,
    speeds: Vec<f64>,
    /// Particle counts of the eq. 7 / eq. 10 and baseline comparisons.
    compared: Vec<usize>,
    /// Test bodies of "the person is not the model", and their particles.
    bodies: Vec<&'static str>,
    person_particles: usize,
}

impl Plan {
    fn new(quick: bool, seed: u64) -> Plan {
        let seeds = if quick { 1..=2 } else { 1..=5 };
        Plan {
            seeds: seeds.map(|k| seed * 100 + k).collect(),
            particles: if quick { vec![6, 25, 100] } else { vec![6, 12, 25, 50, 100, 200] },
            speeds: if quick { vec![0.25, 1.0, 4.0] } else { vec![0.03, 0.25, 1.0, 2.0, 4.0, 8.0] },
            compared: if quick { vec![6] } else { vec![6, 200] },
            // The model itself, the thinnest and thickest builds, and clothes.
            bodies: if quick { vec!["capsules", "heavy"] } else { vec!["capsules", "slight", "heavy", "skirt"] },
            person_particles: if quick { 6 } else { 25 },
        }
    }
}

/// The trials' working folder, its sequences and runs.
struct Work {
    dir: PathBuf,
    vocab: PathBuf,
    /// Vocabularies once read, by path.
    read: RefCell<HashMap<PathBuf, Arc<Vocabulary>>>,
    /// The tracker seeds every setting runs.
    seeds: Vec<u64>,
    bar: ProgressBar,
    /// Runs already made, by folder name: trials that share a setting (trial
    /// one's 6 particles is also the eq. 10 and the primitives' baseline
    /// row) track it once.
    done: RefCell<HashMap<String, RunScore>>,
}

/// Where a setting goes in its trial: series, x category, what it sets.
struct Label<'a> {
    series: &'a str,
    x: String,
    params: serde_json::Value,
}

/// One way of tracking that a trial compares: its series, what it sets,
/// and how it tracks (the particle count is the trial's).
struct Variant<'a> {
    series: &'a str,
    params: serde_json::Value,
    how: How,
}

/// How a setting tracks: the clip options the trials vary, the others at
/// `imitate track`'s defaults.
#[derive(Clone, Copy, Debug)]
struct How {
    particles: usize,
    lookahead: usize,
    /// Eq. 10 rather than eq. 7.
    feedback: bool,
    calibrate: bool,
    /// The camera estimated from the frames, not the one rendered beside them.
    estimate_camera: bool,
    /// The full-space annealed filter instead of the primitives'.
    full_space: bool,
}

impl How {
    /// Eq. 10 with `particles` per primitive, the rest as `track`'s defaults.
    fn eq10(particles: usize) -> How {
        let defaults = ClipOptions::default();
        How {
            particles,
            lookahead: defaults.lookahead,
            feedback: true,
            calibrate: true,
            estimate_camera: false,
            full_space: false,
        }
    }

    /// Eq. 10 with everything else as `track`'s defaults.
    fn standard() -> How {
        How::eq10(ClipOptions::default().particles)
    }

    /// The folder-name part that tells this setting from the others.
    fn name(&self) -> String {
        let mut name =
            format!("p{}_k{}_{}", self.particles, self.lookahead, if self.feedback { "eq10" } else { "eq7" });
        for (on, what) in
            [(!self.calibrate, "canonical"), (self.estimate_camera, "auto-camera"), (self.full_space, "full-space")]
        {
            if on {
                name += &format!("_{what}");
            }
        }
        name
    }

    fn options(&self, seed: u64) -> ClipOptions {
        ClipOptions {
            particles: self.particles,
            lookahead: self.lookahead,
            seed,
            feedback: self.feedback,
            calibrate: self.calibrate,
            camera: if self.estimate_camera { CameraChoice::Auto } else { CameraChoice::Beside },
            baseline: self.full_space.then_some(Baseline::FullSpace),
            ..ClipOptions::default()
        }
    }
}

/// A rendered video: its name, frames and truth.
#[derive(Clone)]
struct Video {
    name: String,
    frames: PathBuf,
    truth: PathBuf,
    /// The take it was filmed from.
    motion: PathBuf,
}

impl Work {
    /// The same folder, seeds and progress, tracking with `vocab`; its runs
    /// join this one's with [`Work::absorb`].
    fn with_vocab(&self, vocab: PathBuf) -> Work {
        Work {
            vocab,
            read: RefCell::default(),
            seeds: self.seeds.clone(),
            bar: self.bar.clone(),
            dir: self.dir.clone(),
            done: RefCell::default(),
        }
    }

    /// Counts `other`'s runs as this one's.
    fn absorb(&self, other: Work) {
        self.done.borrow_mut().extend(other.done.take());
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    fn step(&self, what: &str) {
        self.bar.set_message(what.to_string());
    }

    /// Renders `bvh` (labelled by `labels`) as seen by a `preset` camera
    /// into `name`.
    fn render(&self, name: &str, bvh: &Path, labels: &Path, preset: Preset) -> anyhow::Result<Video> {
        self.film(name, bvh, labels, Camera::preset(preset, DEFAULT_SIZE.0, DEFAULT_SIZE.1)?, None)
    }

    /// Films `bvh` (labelled by `labels`) through `camera`, performed by
    /// `build` (`None`: the tracker's capsules), into `name`, as `render`
    /// does by default otherwise.
    fn film(
        &self,
        name: &str,
        bvh: &Path,
        labels: &Path,
        camera: Camera,
        build: Option<Build>,
    ) -> anyhow::Result<Video> {
        self.step(&format!("render {name}"));
        let out = self.path(name);
        let (motion, activities) = read_take(bvh, Some(labels), &RetargetOptions::default(), &mut ())?;
        let filming = Filming { build, ..Filming::new(camera) };
        film(&motion, activities.as_deref(), &filming, &out, &|| {}).with_context(|| bvh.display().to_string())?;
        Ok(Video {
            name: name.to_string(),
            frames: out.join("frames"),
            truth: out.join("truth.csv"),
            motion: bvh.to_path_buf(),
        })
    }

    /// A synthetic take: `--sequence` of `activities` (or one activity's
    /// take), `reps`, at `speed`, retimed by `retime` (for speeds beyond
    /// synth's range), rendered by `camera`.
    fn synth(
        &self,
        name: &str,
        activities: &[Activity],
        reps: usize,
        seed: u64,
        retime: f64,
        preset: Preset,
    ) -> anyhow::Result<Video> {
        self.step(&format!("synth {name}"));
        let dir = self.path(&format!("{name}-motion"));
        files::write_sequence(&dir, activities, &SynthOptions { repetitions: reps, seed, ..SynthOptions::default() })?;
        let bvh = dir.join(files::SEQUENCE_FILE);
        if retime != 1.0 {
            let mut motion = imitate::mocap::bvh::read_bvh(&bvh)?;
            motion.frame_time_s /= retime;
            let mut bytes = Vec::new();
            imitate::mocap::bvh::write_bvh(&motion, &mut bytes)?;
            std::fs::write(&bvh, bytes).with_context(|| format!("{}: cannot write", bvh.display()))?;
        }
        self.render(name, &bvh, &dir.join(files::LABELS_FILE), preset)
    }

    /// The folder of the run of `video` tracked `how` with `seed`.
    fn run_dir(&self, video: &Video, how: How, seed: u64) -> PathBuf {
        self.path(&format!("runs/{}_{}_seed{seed}", video.name, how.name()))
    }

    /// Tracks `video` `how` with `seed`, and scores it (once).
    fn track(&self, video: &Video, how: How, seed: u64) -> anyhow::Result<RunScore> {
        let out = self.run_dir(video, how, seed);
        let key = out.display().to_string();
        if let Some(done) = self.done.borrow().get(&key) {
            return Ok(done.clone());
        }
        self.step(&format!("track {} {}", video.name, how.name()));
        let vocabulary = self.vocabulary()?;
        let tracked = track_clip_with(&video.frames, &self.vocab, vocabulary, &how.options(seed), &mut |_| {})?;
        tracked.write(&out, true)?;
        let run = Run::read(&out)?;
        let truth = read_track(&video.truth)?;
        let metrics = score(&run.track, &truth, &run.primitives, SETTLE_S)?;
        let scored = RunScore {
            upper_body_mm: metrics.upper_body_mm,
            hand_mm: metrics.hand_mm,
            // The baseline names no activity: it has no recognition to score.
            recognition: metrics.recognition.recognition_accuracy_settled.filter(|_| run.summary.baseline.is_none()),
            frames_per_second: run.summary.timing.frames_per_second,
            evaluations_per_frame: run.summary.likelihood_evaluations_per_frame,
        };
        self.done.borrow_mut().insert(key, scored.clone());
        self.bar.inc(1);
        Ok(scored)
    }

    /// Learns a vocabulary from `inputs` labelled by `labels` with `vocab
    /// build`'s defaults (one cluster per label when `by_label`) and saves
    /// it as `out`.
    fn build_vocabulary(&self, inputs: Vec<PathBuf>, labels: &Path, by_label: bool, out: &Path) -> anyhow::Result<()> {
        let mut params = BuildParams::standard();
        params.cluster = ClusterParams::default().by_label(by_label).check()?;
        let takes = Takes { inputs, labels: Some(labels.to_path_buf()), ..Takes::default() };
        let Built { mut vocabulary, .. } = learn::build(&takes, &params, &mut ())?;
        vocabulary.save(out)?;
        Ok(())
    }

    /// The vocabulary at `vocab`, read once.
    fn vocabulary(&self) -> anyhow::Result<Arc<Vocabulary>> {
        self.vocabulary_at(&self.vocab)
    }

    /// The vocabulary at `path`, read once: the trials' own or another
    /// trial's kept alongside.
    fn vocabulary_at(&self, path: &Path) -> anyhow::Result<Arc<Vocabulary>> {
        if let Some(read) = self.read.borrow().get(path) {
            return Ok(read.clone());
        }
        let read = Arc::new(Vocabulary::load(path)?);
        self.read.borrow_mut().insert(path.to_path_buf(), read.clone());
        Ok(read)
    }

    /// One setting over every seed.
    fn setting(&self, video: &Video, label: Label, how: How) -> anyhow::Result<Setting> {
        let runs = self.seeds.iter().map(|&seed| self.track(video, how, seed)).collect::<anyhow::Result<_>>()?;
        let params = label.params.as_object().cloned().unwrap_or_default();
        Ok(Setting { series: label.series.into(), x: label.x, params, runs })
    }

    /// Each of `variants` at each of `counts` particles per primitive, on
    /// `video`: a trial's settings, the count on the x axis.
    fn per_particles(&self, video: &Video, counts: &[usize], variants: &[Variant]) -> anyhow::Result<Vec<Setting>> {
        let mut settings = Vec::new();
        for &n in counts {
            for v in variants {
                let mut params = v.params.clone();
                params["particles"] = n.into();
                let how = How { particles: n, ..v.how };
                settings.push(self.setting(video, Label { series: v.series, x: n.to_string(), params }, how)?);
            }
        }
        Ok(settings)
    }
}

/// The filmstrip of a run, as a trial's picture.
fn strip(run_dir: &Path, video: &Video, name: &str, caption: &str) -> anyhow::Result<Picture> {
    let run = Run::read(run_dir)?;
    let truth = read_track(&video.truth)?;
    let camera = tracked_camera(&run)?;
    let picks = pick_frames(run.track.frame.len(), 8);
    let observed = silhouettes(&video.frames, run.track.frame.len(), &picks, camera.width(), None)?;
    let png = filmstrip(&camera, &run.track, Some(&truth), &picks, &observed);
    Ok(Picture { name: name.into(), png, svg: None, caption: caption.into() })
}

/// Figure 8 of a run.
fn figure8(run_dir: &Path, truth: &Track) -> anyhow::Result<Picture> {
    let run = Run::read(run_dir)?;
    let figure = figures::recognition(&run, Some(truth), FilterParams::standard(1, 1, 1.0).sharpness);
    Ok(Picture {
        name: "figure8".into(),
        png: figure.png(),
        svg: Some(figure.svg()),
        caption: "Figure 8: attractor progress per primitive (marker width: relative likelihood) and the activity \
                  probabilities over time, true activities shaded (first seed, 6 particles, eq. 10)."
            .into(),
    })
}

/// The right wrist's speed (m/s) between frames with a true activity
/// (not rest): its mean and 95th percentile.
fn hand_speed(truth: &Track) -> (f64, f64) {
    let wrist = imitate::mocap::body::Joint::RightWrist.index();
    let mut speeds: Vec<f64> = (1..truth.frame.len())
        .filter(|&f| truth.activity[f].as_deref().is_some_and(|a| a != "rest"))
        .map(|f| truth.joints[f][wrist].distance(truth.joints[f - 1][wrist]) / (truth.time_s[f] - truth.time_s[f - 1]))
        .collect();
    if speeds.is_empty() {
        return (0.0, 0.0);
    }
    speeds.sort_by(f64::total_cmp);
    let p95 = speeds[((speeds.len() - 1) as f64 * 0.95).round() as usize];
    (speeds.iter().sum::<f64>() / speeds.len() as f64, p95)
}

/// This machine in a line: processor, cores, memory.
fn machine() -> String {
    let read = |path: &str| std::fs::read_to_string(path).unwrap_or_default();
    let field = |text: &str, key: &str| {
        text.lines().find(|l| l.starts_with(key)).and_then(|l| l.split(':').nth(1)).map(|v| v.trim().to_string())
    };
    let cpu = field(&read("/proc/cpuinfo"), "model name").unwrap_or_else(|| std::env::consts::ARCH.to_string());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let memory = field(&read("/proc/meminfo"), "MemTotal")
        .and_then(|m| m.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(String::new(), |kb| format!(", {:.0} GiB", kb / 1024.0 / 1024.0));
    format!("{cpu}, {cores} logical cores{memory}, {}", std::env::consts::OS)
}

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    refuse_nonempty(&args.output, args.force)?;
    if let Some(vocab) = &args.vocab {
        let n = Vocabulary::load(vocab)?.primitives().len();
        if n < 2 {
            return Err(UsageError(format!(
                "--vocab {}: {n} primitive; recognition needs at least 2",
                vocab.display()
            ))
            .into());
        }
    }
    let temporary = match &args.work {
        Some(_) => None,
        None => Some(tempfile_dir(&args.output)?),
    };
    let dir = args.work.clone().unwrap_or_else(|| temporary.as_ref().expect("made above").clone());
    std::fs::create_dir_all(dir.join("runs")).with_context(|| format!("{}: cannot create", dir.display()))?;
    let result = evaluate(&args, global, &dir);
    if let Some(t) = temporary {
        let _ = std::fs::remove_dir_all(t);
    }
    result
}

/// A folder beside `output` for the trials' files (removed afterwards).
fn tempfile_dir(output: &Path) -> anyhow::Result<PathBuf> {
    let parent = output.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).with_context(|| format!("{}: cannot create", parent.display()))?;
    // A fixed name, so the vocabulary built there (which records its
    // sources' paths) is the same file on every run.
    let name = format!(".{}.eval-work", output.file_name().map_or("report".into(), |n| n.to_string_lossy()));
    let dir = parent.join(name);
    std::fs::create_dir_all(&dir).with_context(|| format!("{}: cannot create", dir.display()))?;
    Ok(dir)
}

fn evaluate(args: &Args, global: Global, dir: &Path) -> anyhow::Result<Outcome> {
    let started = std::time::Instant::now();
    let plan = Plan::new(args.quick, args.seed);
    let bar = super::progress(global, 0, "eval");
    let done = RefCell::new(HashMap::new());
    let mut work = Work {
        dir: dir.to_path_buf(),
        vocab: PathBuf::new(),
        read: RefCell::default(),
        seeds: plan.seeds.clone(),
        bar,
        done,
    };
    work.vocab = match &args.vocab {
        Some(v) => v.clone(),
        None => paper_vocabulary(&work, args.seed)?,
    };
    let vocabulary = Vocabulary::load(&work.vocab)?;
    let held_out = args.seed + 1000;
    // Distinct settings (trials share some): trial one, eq. 7, speed with the
    // punch, side and overhead, the full-space baseline, the real takes, the
    // person who is not the model.
    let settings = plan.particles.len()
        + plan.compared.len()
        + 2 * (plan.speeds.len() + 1)
        + 2
        + plan.compared.len()
        + 2
        + 6 * plan.bodies.len();
    work.bar.set_length((settings * plan.seeds.len()) as u64);
    let front = work.synth("front", SEQUENCE, 3, held_out, 1.0, Preset::Front)?;
    let first = work.run_dir(&front, How::eq10(plan.particles[0]), plan.seeds[0]);
    let mut trials = vec![
        trial_one(&work, &plan, &front, &first)?,
        recognition(&work, &plan, &front, &first)?,
        speed(&work, &plan, held_out)?,
        viewpoint(&work, &front, held_out)?,
        baseline(&work, &plan, &front)?,
        person::trial(&work, &plan, &front)?,
    ];
    if let Some(real) = real_trial(&work, &args.real)? {
        trials.push(real);
    }
    let (mut tables, styles) = mocap::section(&work, &args.mocap)?;
    trials.extend(styles);
    tables.push(imitation::table(&work, &front.motion, &first, &front.truth, &args.real)?);
    let mut table_timing = Vec::new();
    if let Some(clips) = &args.real_video {
        let vocab = video::mocap_vocabulary(&work, &args.mocap)?;
        let (table, timing) = video::section(&work, clips, args.video_reference.as_deref(), &vocab)?;
        tables.push(table);
        table_timing = timing;
    }
    work.bar.finish_and_clear();

    let first_run = Run::read(&first)?;
    let first_metrics = score(&first_run.track, &read_track(&front.truth)?, &first_run.primitives, SETTLE_S)?;
    let provenance = Provenance {
        command: format!(
            "imitate eval{}{}{}{} --seed {}",
            if args.quick { " --quick" } else { "" },
            args.vocab.as_ref().map_or(String::new(), |v| format!(" --vocab {}", v.display())),
            args.real_video.as_ref().map_or(String::new(), |v| format!(" --real-video {}", v.display())),
            args.video_reference.as_ref().map_or(String::new(), |v| format!(" --video-reference {}", v.display())),
            args.seed
        ),
        seed: args.seed,
        quick: args.quick,
        seeds: plan.seeds.clone(),
        vocabulary: serde_json::json!({
            "checksum": vocabulary.checksum().map(|c| format!("{c:08x}")),
            "primitives": vocabulary.primitives().iter()
                .map(|p| serde_json::json!({"name": p.name(), "label": p.majority_label()}))
                .collect::<Vec<_>>(),
        }),
    };
    let confusion = &first_metrics.recognition.confusion;
    let files = eval_report(&provenance, &trials, &tables, confusion, &table_timing, &machine());
    let shown = args.output.display().to_string();
    let io = |e: std::io::Error| anyhow::anyhow!("{shown}: cannot write: {e}");
    let write = |d: &Path| files.iter().try_for_each(|(name, bytes)| std::fs::write(d.join(name), bytes)).map_err(io);
    write_dir_atomic(&args.output, write, io)?;
    let seconds = started.elapsed().as_secs_f64();
    let runs = work.done.borrow().len();
    let report = args.output.join("index.html");
    super::note(
        global,
        &format!("eval: {} trials, {runs} runs in {seconds:.0} s → {}", trials.len(), report.display()),
    );
    Ok(Outcome::Success)
}

/// The activities of trial one, the viewpoints and the demo.
pub(super) const SEQUENCE: &[Activity] = &[Activity::Circles, Activity::WaveH, Activity::WaveV];

/// A vocabulary of the paper's four activities, 12 synthetic repetitions
/// each.
fn paper_vocabulary(work: &Work, seed: u64) -> anyhow::Result<PathBuf> {
    work.step("vocabulary");
    let train = work.path("train");
    let activities = [Activity::Circles, Activity::WaveH, Activity::WaveV, Activity::Punch];
    let options = SynthOptions { repetitions: 12, seed, ..SynthOptions::default() };
    files::write_activities(&train, &activities, &options, &mut |_, _| {})?;
    let vocab = work.path("paper.vocab");
    work.build_vocabulary(vec![train.clone()], &train.join(files::LABELS_FILE), false, &vocab)?;
    Ok(vocab)
}

/// Trial one: error against particles per primitive.
fn trial_one(work: &Work, plan: &Plan, front: &Video, first: &Path) -> anyhow::Result<Trial> {
    let eq10 = Variant { series: "eq. 10", params: serde_json::json!({}), how: How::eq10(0) };
    Ok(Trial {
        key: "particles".into(),
        title: "Trial one: particles per primitive".into(),
        about: format!(
            "Hand circles, horizontal waving, vertical waving (3 repetitions each, held-out motion, front camera, \
             160×120, 15 fps, light noise), tracked with eq. 10 at each number of particles per primitive; {} seeds.",
            plan.seeds.len()
        ),
        x_label: "particles per primitive".into(),
        charts: vec![Measure::UpperBody, Measure::Recognition],
        settings: work.per_particles(front, &plan.particles, &[eq10])?,
        pictures: vec![strip(
            first,
            front,
            "filmstrip-front",
            "Trial one, 6 particles: silhouette with the estimate (blue) and truth (orange) from the camera, and \
             from above.",
        )?],
    })
}

/// Recognition: eq. 7 against eq. 10, and Figure 8.
fn recognition(work: &Work, plan: &Plan, front: &Video, first: &Path) -> anyhow::Result<Trial> {
    let variants = [
        Variant {
            series: "eq. 7",
            params: serde_json::json!({"recognition": "eq7"}),
            how: How { feedback: false, ..How::eq10(0) },
        },
        Variant { series: "eq. 10", params: serde_json::json!({"recognition": "eq10"}), how: How::eq10(0) },
    ];
    Ok(Trial {
        key: "recognition".into(),
        title: "Recognition: eq. 7 against eq. 10".into(),
        about: "The trial-one sequence; eq. 7 normalizes the primitives' likelihoods each frame, eq. 10 also weighs \
                each by its recent probability."
            .into(),
        x_label: "particles per primitive".into(),
        charts: vec![Measure::Recognition],
        settings: work.per_particles(front, &plan.compared, &variants)?,
        pictures: vec![figure8(first, &read_track(&front.truth)?)?],
    })
}

/// The bending cone (K = 5) and the straight line (K = 1) on `video`.
fn cone_and_line(work: &Work, video: &Video, x: &str, params: serde_json::Value) -> anyhow::Result<Vec<Setting>> {
    let mut settings = Vec::new();
    for (k, series) in [(5, "bending cone, K = 5"), (1, "straight line, K = 1")] {
        let mut params = params.clone();
        params["lookahead"] = k.into();
        let label = Label { series, x: x.to_string(), params };
        settings.push(work.setting(video, label, How { lookahead: k, ..How::standard() })?);
    }
    Ok(settings)
}

/// Trial two: one activity from slow to fast, and a fast punch.
fn speed(work: &Work, plan: &Plan, held_out: u64) -> anyhow::Result<Trial> {
    let mut settings = Vec::new();
    let mut fastest = None;
    for &s in &plan.speeds {
        // At least 4 s of motion at every speed.
        let reps = ((4.0 * s).ceil() as usize).clamp(2, 40);
        let video = work.synth(&format!("speed{s}"), &[Activity::WaveH], reps, held_out, s, Preset::Front)?;
        let (hand, peak) = hand_speed(&read_track(&video.truth)?);
        let params = serde_json::json!({"speed": s, "hand_m_per_s": hand, "hand_p95_m_per_s": peak});
        settings.extend(cone_and_line(work, &video, &format!("{s}× ({hand:.2}, {peak:.2} m/s)"), params)?);
        fastest = Some((video, s));
    }
    let punch = work.synth("punch", &[Activity::Punch], 4, held_out, 4.0, Preset::Front)?;
    let (hand, peak) = hand_speed(&read_track(&punch.truth)?);
    let params = serde_json::json!({"speed": 4.0, "hand_m_per_s": hand, "hand_p95_m_per_s": peak, "activity": "punch"});
    settings.extend(cone_and_line(work, &punch, &format!("punch 4× ({hand:.2}, {peak:.2} m/s)"), params)?);
    let (fast, top) = fastest.expect("the plan has speeds");
    let cone = How { lookahead: 5, ..How::standard() };
    Ok(Trial {
        key: "speed".into(),
        title: "Trial two: speed".into(),
        about: "Horizontal waving played from slow to fast, and a punch at 4× (in brackets the hand's mean and \
                95th-percentile speed, measured on the rendered truth), tracked with 6 particles and eq. 10 by the bending cone (K = 5) and the \
                straight-line model (K = 1)."
            .into(),
        x_label: "speed (hand speed: mean, 95th percentile)".into(),
        charts: vec![Measure::UpperBody, Measure::Recognition],
        settings,
        pictures: vec![
            strip(
                &work.run_dir(&fast, cone, work.seeds[0]),
                &fast,
                "filmstrip-fast",
                &format!("Trial two at {top}× (as Figure 6)."),
            )?,
            strip(
                &work.run_dir(&punch, cone, work.seeds[0]),
                &punch,
                "filmstrip-punch",
                "The fast punch (as Figure 5).",
            )?,
        ],
    })
}

/// Viewpoint: the trial-one sequence from the front, the side and above.
fn viewpoint(work: &Work, front: &Video, held_out: u64) -> anyhow::Result<Trial> {
    let mut settings = Vec::new();
    let mut overhead = None;
    for preset in [Preset::Front, Preset::Side, Preset::Overhead] {
        let camera = preset.name();
        let video = match preset {
            Preset::Front => front.clone(),
            _ => work.synth(camera, SEQUENCE, 3, held_out, 1.0, preset)?,
        };
        for (n, series) in [(6, "6 particles"), (25, "25 particles")] {
            let params = serde_json::json!({"camera": camera, "particles": n});
            let label = Label { series, x: camera.into(), params };
            settings.push(work.setting(&video, label, How::eq10(n))?);
        }
        overhead = Some(video);
    }
    let overhead = overhead.expect("overhead comes last");
    Ok(Trial {
        key: "viewpoint".into(),
        title: "Viewpoint".into(),
        about: "The trial-one sequence seen from the front, the side and overhead (70° down), with 6 and 25 \
                particles per primitive, eq. 10."
            .into(),
        x_label: "camera".into(),
        charts: vec![Measure::UpperBody, Measure::Recognition],
        settings,
        pictures: vec![strip(
            &work.run_dir(&overhead, How::eq10(6), work.seeds[0]),
            &overhead,
            "filmstrip-overhead",
            "Overhead camera (as Figure 7).",
        )?],
    })
}

/// The primitives against the full-space annealed filter at equal budget.
fn baseline(work: &Work, plan: &Plan, front: &Video) -> anyhow::Result<Trial> {
    let variants = [
        Variant {
            series: "primitives",
            params: serde_json::json!({"follower": "primitives"}),
            // Both draw the canonical body, so the budgets are the followers' alone.
            how: How { calibrate: false, ..How::eq10(0) },
        },
        Variant {
            series: "full-space annealed filter",
            params: serde_json::json!({"follower": "full_space"}),
            how: How { feedback: false, full_space: true, ..How::eq10(0) },
        },
    ];
    Ok(Trial {
        key: "baseline".into(),
        title: "Baseline: full-space annealed particle filter".into(),
        about: "The trial-one sequence tracked by the primitives' filters and by one annealed particle filter over \
                every joint angle and the root (Deutscher, Blake & Reid 2000) spending the same likelihood \
                evaluations per frame; neither calibrates the body."
            .into(),
        x_label: "particles per primitive (the budget)".into(),
        charts: vec![Measure::UpperBody],
        settings: work.per_particles(front, &plan.compared, &variants)?,
        pictures: vec![],
    })
}

/// Real motion: waving and boxing from the real captures, tracked with a
/// vocabulary of the other captures; `None` when the folder is absent.
fn real_trial(work: &Work, real: &Path) -> anyhow::Result<Option<Trial>> {
    let labels = real.join("labels.csv");
    if !labels.is_file() {
        return Ok(None);
    }
    work.step("real vocabulary");
    let tracked = ["wave_hello.bvh", "boxing.bvh"];
    let mut takes: Vec<PathBuf> = std::fs::read_dir(real)
        .with_context(|| format!("{}: cannot read", real.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
        .filter(|p| !tracked.iter().any(|t| p.file_name().is_some_and(|n| n == *t)))
        .collect();
    takes.sort();
    // The waving takes share one label, so a waving primitive stands for waving.
    let text = std::fs::read_to_string(&labels).with_context(|| format!("{}: cannot read", labels.display()))?;
    let wave = |line: &str| {
        ["wave_left", "wave_right", "wave_both"]
            .iter()
            .fold(line.to_string(), |l, w| l.replace(&format!(",{w},"), ",wave,"))
    };
    let relabelled: String = text.lines().map(|l| wave(l) + "\n").collect();
    let real_labels = work.path("real-labels.csv");
    std::fs::write(&real_labels, relabelled).with_context(|| format!("{}: cannot write", real_labels.display()))?;
    let vocab = work.path("real.vocab");
    work.build_vocabulary(takes.clone(), &real_labels, false, &vocab)?;
    let real_work = work.with_vocab(vocab);
    let mut settings = Vec::new();
    for take in tracked {
        let name = take.trim_end_matches(".bvh");
        let bvh = real.join(take);
        let mut video = real_work.render(&format!("real-{name}"), &bvh, &real_labels, Preset::Front)?;
        // A silhouette cannot tell front from back: film a performer who
        // faces away from behind.
        if read_track(&video.truth)?.joints.first().is_some_and(faces_away) {
            let mut spec = Preset::Front.spec(DEFAULT_SIZE.0, DEFAULT_SIZE.1);
            spec.position[2] = -spec.position[2];
            let behind = Camera::new(spec, "behind")?;
            video = real_work.film(&format!("real-{name}"), &bvh, &real_labels, behind, None)?;
        }
        let label = Label { series: "eq. 10", x: name.into(), params: serde_json::json!({"take": take}) };
        settings.push(real_work.setting(&video, label, How::standard())?);
    }
    work.absorb(real_work);
    Ok(Some(Trial {
        key: "real".into(),
        title: "Real motion".into(),
        about: format!(
            "Waving and boxing from {}, rendered from the front (from behind for a performer facing away) and \
             tracked with a vocabulary built from the other {} captures (the waving takes labelled `wave`), 6 \
             particles, eq. 10. That vocabulary has no punching primitive, so boxing has no recognition figure.",
            real.display(),
            takes.len()
        ),
        x_label: "take".into(),
        charts: vec![Measure::UpperBody],
        settings,
        pictures: vec![],
    }))
}

/// Whether a body faces away from +z (the front camera), from its hips.
fn faces_away(joints: &[glam::DVec3; imitate::mocap::body::JOINTS]) -> bool {
    use imitate::mocap::body::Joint;
    let across = joints[Joint::RightHip.index()] - joints[Joint::LeftHip.index()];
    // Facing +z, the left hip is at +x of the right one.
    across.x > 0.0
}
