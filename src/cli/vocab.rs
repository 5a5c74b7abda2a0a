//! `imitate vocab build` (every learning stage in one go) and `imitate
//! vocab info`.

use super::learn::{ClusterArgs, EmbedArgs, FitArgs, SegmentArgs, TakesArgs};
use super::{Global, Outcome, count, note, peak_resident_mb, write_stdout};
use imitate::vocab::cluster::Choice;
use imitate::vocab::container::FORMAT_VERSION;
use imitate::vocab::learn::{self, Built, Listener};
use imitate::vocab::pipeline::BuildParams;
use imitate::vocab::vocabulary::Vocabulary;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Build and look at vocabularies.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, clap::Subcommand)]
pub enum Command {
    Build(Box<BuildArgs>),
    Info(InfoArgs),
}

/// Learn a vocabulary from BVH takes: segment, embed, cluster, fit and
/// export in one go (each stage's settings as in its own subcommand), and
/// print how long each stage took.
#[derive(Debug, clap::Args)]
pub struct BuildArgs {
    #[command(flatten)]
    pub takes: TakesArgs,
    /// The vocabulary file to write, e.g. `vocab/NAME.vocab`.
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub segment: SegmentArgs,
    #[command(flatten)]
    pub embed: EmbedArgs,
    #[command(flatten)]
    pub cluster: ClusterArgs,
    #[command(flatten)]
    pub fit: FitArgs,
}

/// Print a vocabulary's primitives: dimensions, variance kept, training
/// frames and sources, and how it was built.
#[derive(Debug, clap::Args)]
pub struct InfoArgs {
    /// A `.vocab` file.
    pub file: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: Args, global: Global) -> anyhow::Result<Outcome> {
    match args.command {
        Command::Build(args) => build(*args, global),
        Command::Info(args) => info(args),
    }
}

/// A spinner per stage on stderr, each stage's time kept.
struct Stages {
    global: Global,
    running: Option<(ProgressBar, &'static str, Instant)>,
    times: Vec<(&'static str, f64)>,
}

impl Stages {
    fn new(global: Global) -> Stages {
        Stages { global, running: None, times: Vec::new() }
    }

    /// Ends the running stage, if any, keeping its time.
    fn finish(&mut self) {
        if let Some((bar, name, started)) = self.running.take() {
            self.times.push((name, started.elapsed().as_secs_f64()));
            bar.finish_and_clear();
        }
    }
}

impl Listener for Stages {
    fn stage(&mut self, name: &'static str) {
        self.finish();
        let bar = if self.global.quiet || !std::io::stderr().is_terminal() {
            ProgressBar::hidden()
        } else {
            let bar = ProgressBar::new_spinner().with_message(name);
            bar.set_style(
                ProgressStyle::with_template("{spinner} {msg:<8} {elapsed_precise}").expect("valid template"),
            );
            bar.enable_steady_tick(Duration::from_millis(100));
            bar
        };
        self.running = Some((bar, name, Instant::now()));
    }

    fn note(&mut self, text: &str) {
        match &self.running {
            Some((bar, ..)) if !self.global.quiet => bar.suspend(|| eprintln!("{text}")),
            _ => note(self.global, text),
        }
    }
}

fn build(args: BuildArgs, global: Global) -> anyhow::Result<Outcome> {
    let params = BuildParams {
        segment: args.segment.params()?,
        embed: args.embed.params()?,
        cluster: args.cluster.params()?,
        fit: args.fit.params()?,
    };
    let mut stages = Stages::new(global);
    let built = learn::build(&args.takes.takes(), &params, &mut stages);
    stages.finish();
    let Built { mut vocabulary, frames } = built?;
    stages.stage("write");
    vocabulary.save(&args.output)?;
    stages.finish();

    note(global, &saved(&vocabulary, &args.output));
    let total: f64 = stages.times.iter().map(|t| t.1).sum();
    let each: Vec<String> = stages.times.iter().map(|(name, s)| format!("{name} {s:.2} s")).collect();
    let memory = peak_resident_mb().map_or(String::new(), |mb| format!("; peak memory {mb:.0} MB"));
    note(global, &format!("time: {}; total {total:.2} s for {frames} frames{memory}", each.join(", ")));
    Ok(Outcome::Success)
}

/// The line saying a vocabulary was written.
pub fn saved(vocabulary: &Vocabulary, path: &Path) -> String {
    let bytes = std::fs::metadata(path).map_or(0, |m| m.len());
    format!(
        "wrote {}: {}, {:.1} KB, CRC-32 {:#010x}",
        path.display(),
        count(vocabulary.primitives().len(), "primitive"),
        bytes as f64 / 1024.0,
        vocabulary.checksum().unwrap_or(0)
    )
}

fn info(args: InfoArgs) -> anyhow::Result<Outcome> {
    let vocabulary = Vocabulary::load(&args.file)?;
    let bytes = std::fs::metadata(&args.file).map_or(0, |m| m.len());
    let checksum = format!("{:#010x}", vocabulary.checksum().unwrap_or(0));
    let text = if args.json {
        let value = vocabulary.info(Some(&args.file), Some(vocabulary.checksum().unwrap_or(0)));
        serde_json::to_string_pretty(&value).expect("JSON serializes") + "\n"
    } else {
        describe(&vocabulary, &args.file, bytes, &checksum)
    };
    write_stdout(&text)?;
    Ok(Outcome::Success)
}

/// `vocab info` as text.
fn describe(vocabulary: &Vocabulary, path: &Path, bytes: u64, checksum: &str) -> String {
    let b = vocabulary.build_info();
    let l = &b.lineage;
    let mut out = vec![
        format!(
            "{}: imitate vocabulary, format {FORMAT_VERSION}, {:.1} KB, CRC-32 {checksum}",
            path.display(),
            bytes as f64 / 1024.0
        ),
        format!(
            "built by imitate {} from {} ({}, {})",
            l.imitate,
            count(b.takes.len(), "take"),
            count(b.frames, "frame"),
            count(b.segments, "segment")
        ),
    ];
    let s = &l.segment;
    out.push(format!("  segment: {:?}, {}–{} s", s.method, s.min_length_s, s.max_length_s).to_lowercase());
    if let Some(e) = &l.embed {
        let kind = if e.temporal {
            format!("ST-Isomap (c_atn {}, c_ctn {})", e.c_atn, e.c_ctn)
        } else {
            "plain Isomap".to_string()
        };
        out.push(format!(
            "  embed:   {kind}, {} neighbours, {} dimensions, {} poses per segment",
            e.neighbors, e.dims, e.resample
        ));
    }
    if let Some(c) = &l.cluster {
        let chosen = c.tried.iter().find(|t| t.k == c.k).map_or(f64::NAN, |t| t.silhouette);
        let how = match c.choice {
            Choice::Given => format!("as given (mean silhouette {chosen:.3})"),
            Choice::Silhouette => format!("chosen by mean silhouette ({chosen:.3})"),
            Choice::ByLabel => format!("one per activity label (mean silhouette {chosen:.3})"),
        };
        out.push(format!("  cluster: k = {} {how}, seed {}", c.k, c.params.seed));
    }
    let f = &b.fit;
    out.push(format!(
        "  fit:     {:.0}% of variance, {}–{} dimensions, {} field neighbours",
        100.0 * f.variance,
        f.min_dims,
        f.max_dims,
        f.neighbors
    ));
    if !b.still.is_empty() {
        out.push(format!("  left out (no motion): {}", b.still.join(", ")));
    }
    out.push(String::new());
    out.push(learn::summary(vocabulary));
    out.push(String::new());
    for p in vocabulary.primitives() {
        let mut files: Vec<(&str, usize)> = Vec::new();
        for s in p.sources() {
            match files.iter_mut().find(|(f, _)| *f == s.file) {
                Some(entry) => entry.1 += 1,
                None => files.push((&s.file, 1)),
            }
        }
        let listed: Vec<String> = files.iter().map(|(f, n)| format!("{f} ×{n}")).collect();
        out.push(format!("{}: {}", p.name(), listed.join(", ")));
    }
    out.join("\n") + "\n"
}
