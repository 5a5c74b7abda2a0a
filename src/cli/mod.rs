//! Argument parsing and one file per subcommand; no algorithms here.
//!
//! Exit codes: 0 success, 1 some inputs failed (each reported), 2 usage
//! error (unknown flag, impossible option value).

mod cluster;
mod demo;
mod embed;
mod eval;
mod execute;
mod export;
mod fit;
mod inspect;
mod learn;
mod render;
mod report;
mod retarget;
mod score;
mod segment;
mod synth;
mod track;
mod vocab;

use clap::{Parser, Subcommand};
use imitate::vision::camera::{Camera, Preset};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::Path;
use std::process::ExitCode;

/// Learn dynamical motion primitives from motion capture and follow a
/// person through one camera.
#[derive(Debug, Parser)]
#[command(name = "imitate", version, about, propagate_version = true)]
struct Cli {
    #[command(flatten)]
    global: Global,
    #[command(subcommand)]
    command: Command,
}

/// Flags every subcommand takes.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct Global {
    /// Print nothing but errors: no progress bars, summaries or warnings.
    #[arg(short, long, global = true)]
    pub quiet: bool,
}

#[derive(Debug, Subcommand)]
enum Command {
    Inspect(inspect::Args),
    Retarget(retarget::Args),
    Synth(synth::Args),
    Segment(segment::Args),
    Embed(embed::Args),
    Cluster(cluster::Args),
    Fit(fit::Args),
    Export(export::Args),
    Vocab(vocab::Args),
    Render(render::Args),
    Track(track::Args),
    Score(score::Args),
    Execute(execute::Args),
    Report(report::Args),
    Eval(eval::Args),
    Demo(demo::Args),
}

/// How a command ended, when it did not fail outright.
pub enum Outcome {
    Success,
    /// Some inputs failed; each has been reported.
    SomeFailed,
}

/// A problem with the options themselves ([`EXIT_USAGE`]).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct UsageError(pub String);

/// The exit code of a command that failed, or of one whose inputs partly
/// failed (each reported), as docs/commands.md, "Exit codes", lists them.
pub const EXIT_FAILED: u8 = 1;
/// The exit code of options that cannot be used (as clap's own).
pub const EXIT_USAGE: u8 = 2;

pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = dispatch(cli);
    match result {
        Ok(Outcome::Success) => ExitCode::SUCCESS,
        Ok(Outcome::SomeFailed) => ExitCode::from(EXIT_FAILED),
        Err(err) => {
            eprintln!("imitate: error: {}", describe(&err));
            let usage = err.downcast_ref::<UsageError>().is_some();
            ExitCode::from(if usage { EXIT_USAGE } else { EXIT_FAILED })
        }
    }
}

fn dispatch(cli: Cli) -> anyhow::Result<Outcome> {
    match cli.command {
        Command::Inspect(args) => inspect::run(args, cli.global),
        Command::Retarget(args) => retarget::run(args, cli.global),
        Command::Synth(args) => synth::run(args, cli.global),
        Command::Segment(args) => segment::run(args, cli.global),
        Command::Embed(args) => embed::run(args, cli.global),
        Command::Cluster(args) => cluster::run(args, cli.global),
        Command::Fit(args) => fit::run(args, cli.global),
        Command::Export(args) => export::run(args, cli.global),
        Command::Vocab(args) => vocab::run(args, cli.global),
        Command::Render(args) => render::run(args, cli.global),
        Command::Track(args) => track::run(args, cli.global),
        Command::Score(args) => score::run(args, cli.global),
        Command::Execute(args) => execute::run(args, cli.global),
        Command::Report(args) => report::run(args, cli.global),
        Command::Eval(args) => eval::run(args, cli.global),
        Command::Demo(args) => demo::run(args, cli.global),
    }
}

/// An error and its causes in one line, leaving out a cause whose text the
/// message already holds (errors that quote their source), and ending with
/// the flag to change where the library's words name only a setting.
fn describe(err: &anyhow::Error) -> String {
    let message = imitate::describe(err.as_ref());
    match err.chain().find_map(flag_hint) {
        Some(hint) if message.contains('\n') => format!("{message}\n({hint})"),
        Some(hint) => format!("{message} ({hint})"),
        None => message,
    }
}

/// The flag behind a library error that a setting caused but only the data
/// could refuse (so no params check names it).
fn flag_hint(cause: &(dyn std::error::Error + 'static)) -> Option<String> {
    use imitate::mocap::retarget::RetargetError;
    use imitate::vocab::cluster::ClusterError;
    use imitate::vocab::pipeline::BuildError;
    let cluster = cause.downcast_ref::<ClusterError>().or(match cause.downcast_ref::<BuildError>() {
        Some(BuildError::Cluster(e)) => Some(e),
        _ => None,
    });
    if let Some(ClusterError::TooManyClusters { k, .. }) = cluster {
        return Some(format!("lower --k {k}, or leave it out to choose k by silhouette"));
    }
    matches!(cause.downcast_ref::<RetargetError>(), Some(RetargetError::Unmapped { .. }))
        .then(|| "pass the mapping file with --map FILE".to_string())
}

/// A progress bar on stderr, hidden when stderr is not a terminal or with
/// `--quiet`.
pub fn progress(global: Global, len: u64, message: &str) -> ProgressBar {
    if global.quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len).with_message(message.to_string());
    bar.set_style(
        ProgressStyle::with_template("{msg:>12} [{bar:30}] {pos}/{len} {elapsed_precise}")
            .expect("the template is valid")
            .progress_chars("=> "),
    );
    bar
}

/// Writes a command's output to stdout. A reader that closed the pipe
/// early (`imitate inspect … | head`) has all it wanted: not an error.
pub fn write_stdout(text: &str) -> std::io::Result<()> {
    use std::io::Write;
    let mut stdout = std::io::stdout().lock();
    match stdout.write_all(text.as_bytes()).and_then(|()| stdout.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => other,
    }
}

/// The process's peak resident set size (Linux `VmHWM`), MB.
pub fn peak_resident_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0 / 1e6)
}

pub use imitate::vocab::learn::count;

/// Prints a note on stderr unless `--quiet`.
pub fn note(global: Global, text: &str) {
    if !global.quiet {
        eprintln!("{text}");
    }
}

/// A learning stage's notes, on stderr unless `--quiet`.
pub struct Notes(pub Global);

impl imitate::vocab::learn::Listener for Notes {
    fn note(&mut self, text: &str) {
        note(self.0, text);
    }
}

/// `--camera`: a preset framed at `width × height`, or a camera.json file
/// (which gives its own size).
pub fn camera(choice: &str, width: u32, height: u32) -> anyhow::Result<Camera> {
    match Preset::from_name(choice) {
        Some(preset) => Camera::preset(preset, width, height).map_err(|e| UsageError(format!("--size: {e}")).into()),
        None if Path::new(choice).is_file() => Ok(Camera::read(Path::new(choice))?),
        None => Err(UsageError(format!(
            "--camera {choice}: neither a preset (front, side, overhead) nor a camera.json file"
        ))
        .into()),
    }
}

/// Refuses an output folder that holds something, unless `force`.
pub fn refuse_nonempty(output: &Path, force: bool) -> anyhow::Result<()> {
    imitate::fsutil::refuse_nonempty(output, force)
        .map_err(|e| anyhow::anyhow!("{e}; choose another folder or pass --force to replace it"))
}
