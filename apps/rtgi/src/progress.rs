//! Progress of a long render on standard error: a bar when that is a
//! terminal, otherwise (CI, cluster job logs) a line every few seconds
//! with the samples done, the rate and the time left.

use std::io::IsTerminal;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Seconds between two progress lines when standard error is not a
/// terminal, unless the environment variable `RTGI_PROGRESS_SECONDS` says otherwise.
const LINE_EVERY: Duration = Duration::from_secs(5);

fn line_every() -> Duration {
    std::env::var("RTGI_PROGRESS_SECONDS")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s >= 0.0)
        .map_or(LINE_EVERY, Duration::from_secs_f64)
}

/// Counts pixel samples as the workers finish them.
#[derive(Debug)]
pub(crate) struct Progress {
    /// Pixel samples this run has to render.
    total: u64,
    /// Pixels per sample, to say samples per pixel.
    pixels: u64,
    /// Samples per pixel done before this run (a resumed render).
    before: u32,
    /// Samples per pixel of the whole job.
    samples: u32,
    done: AtomicU64,
    start: Instant,
    bar: Option<ProgressBar>,
    last_line: Mutex<Instant>,
    line_every: Duration,
    /// Say, once every pixel has its first sample, how long the whole
    /// render will take (the course framework's "Will take around").
    forecast: std::sync::atomic::AtomicBool,
    finished: std::sync::atomic::AtomicBool,
}

impl Progress {
    /// Progress of rendering `samples - before` samples of `pixels` pixels.
    pub(crate) fn new(pixels: u64, before: u32, samples: u32) -> Self {
        let total = pixels * (samples - before) as u64;
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
            if let Ok(style) =
                ProgressStyle::with_template("{bar:40} {percent:>3}% {elapsed_precise} (eta {eta}) {msg}")
            {
                bar.set_style(style);
            }
            bar
        });
        let start = Instant::now();
        let last_line = Mutex::new(start);
        Self {
            total,
            pixels,
            before,
            samples,
            done: AtomicU64::new(0),
            start,
            bar,
            last_line,
            line_every: line_every(),
            forecast: std::sync::atomic::AtomicBool::new(false),
            finished: std::sync::atomic::AtomicBool::new(false),
        }
    }

    /// Says, once every pixel has a sample, how long the render will take.
    pub(crate) fn with_forecast(self) -> Self {
        self.forecast.store(true, Ordering::Relaxed);
        self
    }

    /// `count` more pixel samples are done (called from the workers).
    pub(crate) fn add(&self, count: u64) {
        let done = self.done.fetch_add(count, Ordering::Relaxed) + count;
        if done >= self.pixels && self.forecast.swap(false, Ordering::Relaxed) {
            let seconds = self.start.elapsed().as_secs_f64();
            let whole = seconds * self.total as f64 / done as f64;
            self.say(&format!("Will take around {} to complete", short_duration(whole)));
        }
        if let Some(bar) = &self.bar {
            bar.set_position(done);
            return;
        }
        let now = Instant::now();
        let Ok(mut last) = self.last_line.try_lock() else { return };
        if now.duration_since(*last) < self.line_every {
            return;
        }
        *last = now;
        let seconds = now.duration_since(self.start).as_secs_f64();
        let rate = done as f64 / seconds.max(1e-9);
        let left = (self.total.saturating_sub(done)) as f64 / rate.max(1e-9);
        let per_pixel = self.before as f64 + done as f64 / self.pixels.max(1) as f64;
        eprintln!(
            "rtgi: {per_pixel:.1}/{} samples per pixel ({:.1}%), {:.2} M samples/s, {} left",
            self.samples,
            100.0 * done as f64 / self.total.max(1) as f64,
            rate * 1e-6,
            duration(left)
        );
    }

    /// A pass was abandoned: its samples no longer count.
    pub(crate) fn set_done(&self, pixel_samples: u64) {
        self.done.store(pixel_samples, Ordering::Relaxed);
        if let Some(bar) = &self.bar {
            bar.set_position(pixel_samples);
        }
    }

    /// A message beside the bar, or on a line of its own.
    pub(crate) fn say(&self, message: &str) {
        match &self.bar {
            Some(bar) => bar.println(message),
            None => eprintln!("rtgi: {message}"),
        }
    }

    pub(crate) fn finish(&self) {
        self.finished.store(true, Ordering::Relaxed);
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }

    /// Whether [`Progress::finish`] was called.
    pub(crate) fn finished(&self) -> bool {
        self.finished.load(Ordering::Relaxed)
    }
}

/// Seconds as "0.42 s" under a minute, else as [`duration`] says them.
pub(crate) fn short_duration(seconds: f64) -> String {
    if seconds < 60.0 { format!("{seconds:.2} s") } else { duration(seconds) }
}

/// Seconds as "1 h 02 min", "3 min 20 s" or "12 s".
pub(crate) fn duration(seconds: f64) -> String {
    if !seconds.is_finite() {
        return "unknown".into();
    }
    let s = seconds.round() as u64;
    match s {
        0..60 => format!("{s} s"),
        60..3600 => format!("{} min {:02} s", s / 60, s % 60),
        _ => format!("{} h {:02} min", s / 3600, (s % 3600) / 60),
    }
}
