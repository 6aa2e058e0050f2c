//! Issue 15's bad-input corpus: every case of `tests/bad_inputs/manifest.txt` (files written by
//! `tests/bad_inputs/gen.py`, plus a folder, a named pipe, standard input, a missing file and
//! unwritable outputs made here) through every command that reads it. Each run: no panic, done
//! within a time limit; an error case exits 1 or 2 with exactly one `gmwm: error:` line (notes
//! and warnings aside) naming the file or the flag and what is wrong, nothing on stdout; a
//! valid input exits 0 with its output written, and `wv`'s first level equals the Haar wavelet
//! variance computed here from the signal gen.py wrote.

use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Duration;

/// Longest a run may take (the corpus files are small: a run takes milliseconds).
const TIME_LIMIT: Duration = Duration::from_secs(60);

/// The commands "all" stands for: every command that reads a recording (`plot` is `plot wv`,
/// `plot-K` is `plot K`).
const ALL: [&str; 12] = [
    "wv",
    "avar",
    "fit",
    "select",
    "calibrate",
    "plot",
    "plot-avar",
    "plot-compare",
    "plot-fit",
    "plot-select",
    "plot-ieee",
    "report",
];

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_inputs")
}

/// One line of the manifest.
#[derive(Debug)]
struct Case {
    name: String,
    file: String,
    flags: Vec<String>,
    commands: Vec<String>,
    ok: bool,
    /// `error summary`: stdout may hold the summary of a finished calibration.
    summary: bool,
    /// `wv1=N`: wv's level 1 checked against the first N samples of gyro_x.
    wv1: Option<usize>,
    f32: bool,
    needles: Vec<String>,
}

fn manifest() -> Vec<Case> {
    let text = std::fs::read_to_string(corpus().join("manifest.txt")).unwrap();
    text.lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|line| {
            let f: Vec<&str> = line.split('|').map(str::trim).collect();
            assert_eq!(f.len(), 6, "six fields: {line}");
            let expect: Vec<&str> = f[4].split_whitespace().collect();
            let commands: Vec<String> = if f[3] == "all" {
                ALL.iter().map(|c| c.to_string()).collect()
            } else {
                f[3].split_whitespace().map(String::from).collect()
            };
            Case {
                name: f[0].to_string(),
                file: f[1].to_string(),
                flags: f[2].split_whitespace().map(String::from).collect(),
                commands,
                ok: match expect[0] {
                    "ok" => true,
                    "error" => false,
                    e => panic!("expect ok or error, not {e}: {line}"),
                },
                wv1: expect
                    .iter()
                    .find_map(|e| e.strip_prefix("wv1="))
                    .map(|n| n.parse().unwrap()),
                f32: expect.contains(&"f32"),
                summary: expect.contains(&"summary"),
                needles: f[5]
                    .split(';')
                    .map(str::trim)
                    .filter(|n| !n.is_empty())
                    .map(String::from)
                    .collect(),
            }
        })
        .collect()
}

/// gen.py's gyro_x.
fn gyro_x(k: usize) -> f64 {
    ((k * 7919 + 13) % 1009) as f64 / 1000.0 - 0.5
}

/// The classical Haar MODWT wavelet variance at level 1 (tau = 2 samples): the mean of
/// ((x_t - x_{t-1}) / 2)^2 over the N - 1 coefficients free of the boundary.
fn haar_level1(n: usize, f32: bool) -> f64 {
    let x: Vec<f64> = (0..n)
        .map(|k| {
            let v = gyro_x(k);
            if f32 {
                f64::from(v as f32)
            } else {
                v
            }
        })
        .collect();
    let s: f64 = x.windows(2).map(|w| ((w[1] - w[0]) / 2.0).powi(2)).sum();
    s / (n - 1) as f64
}

/// What a run needs around the case: the FILE argument and, for a pipe or standard input,
/// the bytes to feed it.
struct Input {
    arg: Option<String>,
    stdin: Option<PathBuf>,
    fifo: Option<(PathBuf, PathBuf)>,
}

fn input(case: &Case, work: &Path, run: usize) -> Input {
    let none = Input {
        arg: None,
        stdin: None,
        fifo: None,
    };
    match case.file.as_str() {
        "~" => none,
        "@dir" => {
            let d = work.join(format!("folder{run}"));
            std::fs::create_dir_all(&d).unwrap();
            Input {
                arg: Some(d.file_name().unwrap().to_string_lossy().into_owned()),
                ..none
            }
        }
        "@missing" => Input {
            arg: Some("no_such_recording.csv".into()),
            ..none
        },
        f if f.starts_with("@fifo:") => {
            let name = format!("pipe{run}.csv");
            let path = work.join(&name);
            let made = std::process::Command::new("mkfifo")
                .arg(&path)
                .status()
                .unwrap();
            assert!(made.success(), "mkfifo");
            Input {
                arg: Some(name),
                fifo: Some((path, work.join(&f["@fifo:".len()..]))),
                ..none
            }
        }
        f if f.starts_with("-<") => Input {
            arg: Some("-".into()),
            stdin: Some(work.join(&f[2..])),
            ..none
        },
        f => Input {
            arg: Some(f.to_string()),
            ..none
        },
    }
}

/// The argument list of `command` on the case.
fn argv(case: &Case, command: &str, file: Option<&str>, work: &Path, run: usize) -> Vec<String> {
    let has = |flag: &str| case.flags.iter().any(|f| f == flag || f.starts_with(flag));
    let mut a: Vec<String> = match command {
        "plot" => vec!["plot".into(), "wv".into()],
        c => match c.strip_prefix("plot-") {
            Some(figure) => vec!["plot".into(), figure.into()],
            None => vec![c.into()],
        },
    };
    a.extend(file.map(String::from));
    let model = match command {
        "fit" | "plot-fit" => Some("WN()"),
        "select" | "plot-select" => Some("AR1()+WN()"),
        "calibrate" | "report" => Some("WN()+RW()"),
        _ => None,
    };
    if let Some(m) = model.filter(|_| !has("--model")) {
        a.extend(["--model".into(), m.into()]);
    }
    let figure = command.starts_with("plot");
    if (figure || command == "report") && !has("-o") && !has("{no-o}") {
        let ext = if figure { "svg" } else { "html" };
        let out = work.join(format!("out{run}.{ext}"));
        a.extend(["-o".into(), out.display().to_string()]);
    }
    let notdir = work.join("a_regular_file").display().to_string();
    for f in &case.flags {
        if f.starts_with('>') || f == "{no-o}" {
            continue;
        }
        a.push(f.replace("{notdir}", &notdir));
    }
    if command == "wv" && case.wv1.is_some() {
        a.push("--json".into());
    }
    a
}

/// Runs `cmd` to its end, killed after [`TIME_LIMIT`].
fn run_with_limit(mut cmd: std::process::Command) -> std::io::Result<std::process::Output> {
    use std::io::Read;
    let mut child = cmd.spawn()?;
    let drain = |r: Option<Box<dyn Read + Send>>| {
        std::thread::spawn(move || {
            let mut buf = Vec::new();
            if let Some(mut r) = r {
                let _ = r.read_to_end(&mut buf);
            }
            buf
        })
    };
    let out = drain(
        child
            .stdout
            .take()
            .map(|r| Box::new(r) as Box<dyn Read + Send>),
    );
    let err = drain(
        child
            .stderr
            .take()
            .map(|r| Box::new(r) as Box<dyn Read + Send>),
    );
    let start = std::time::Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break status;
        }
        if start.elapsed() > TIME_LIMIT {
            let _ = child.kill();
            break child.wait()?;
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    Ok(std::process::Output {
        status,
        stdout: out.join().unwrap_or_default(),
        stderr: err.join().unwrap_or_default(),
    })
}

/// Runs one (case, command); `Err` says what is wrong.
fn check(case: &Case, command: &str, work: &Path, run: usize) -> Result<(), String> {
    let input = input(case, work, run);
    let args = argv(case, command, input.arg.as_deref(), work, run);
    let shown = format!("gmwm {}", args.join(" "));
    let mut cmd = std::process::Command::new(assert_cmd::cargo::cargo_bin("gmwm"));
    cmd.current_dir(work).args(&args);
    let full = case.flags.iter().any(|f| f == ">/dev/full");
    cmd.stdout(if full {
        Stdio::from(std::fs::File::create("/dev/full").unwrap())
    } else {
        Stdio::piped()
    });
    cmd.stderr(Stdio::piped());
    cmd.stdin(match &input.stdin {
        Some(p) => Stdio::from(std::fs::File::open(p).unwrap()),
        None => Stdio::null(),
    });
    // the pipe's writer blocks until gmwm opens it; if gmwm never does, the test opens it
    let writer = input.fifo.as_ref().map(|(pipe, src)| {
        let (pipe, src) = (pipe.clone(), src.clone());
        std::thread::spawn(move || {
            if let Ok(mut w) = std::fs::OpenOptions::new().write(true).open(&pipe) {
                let _ = std::io::Write::write_all(&mut w, &std::fs::read(src).unwrap());
            }
        })
    });
    let out = run_with_limit(cmd).map_err(|e| format!("{shown}: {e}"))?;
    if let (Some(w), Some((pipe, _))) = (writer, &input.fifo) {
        if !w.is_finished() {
            let _ = std::fs::read(pipe);
        }
        let _ = w.join();
    }
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let fail = |what: &str| Err(format!("{shown}: {what}\n  stderr: {stderr:?}"));
    if stderr.contains("panicked") || out.status.code() == Some(101) {
        return fail("panicked");
    }
    let Some(code) = out.status.code() else {
        return fail("killed (by a signal or the time limit)");
    };
    let errors: Vec<&str> = stderr
        .lines()
        .filter(|l| !l.starts_with("gmwm: warning: ") && !l.starts_with("gmwm: note: "))
        .filter(|l| !l.starts_with("  ")) // a note's continuation
        .collect();
    let file = input.arg.clone().unwrap_or_default();
    let needles: Vec<String> = case
        .needles
        .iter()
        .map(|n| n.replace("{file}", &file))
        .collect();
    if case.ok {
        if code != 0 {
            return fail(&format!("exit code {code}, expected success"));
        }
        if stderr.contains("error:") {
            return fail("an error line on success");
        }
        if let Some(n) = needles.iter().find(|n| !stderr.contains(n.as_str())) {
            return fail(&format!("{n:?} not on stderr"));
        }
        match command {
            c if c.starts_with("plot") || c == "report" => {
                let written = std::fs::read_dir(work)
                    .unwrap()
                    .filter_map(|e| e.ok())
                    .any(|e| {
                        e.file_name()
                            .to_string_lossy()
                            .starts_with(&format!("out{run}."))
                    });
                if !written {
                    return fail("no figure or report written");
                }
            }
            _ if stdout.trim().is_empty() => return fail("nothing on stdout"),
            _ => {}
        }
        if let (Some(n), "wv") = (case.wv1, command) {
            let doc: serde_json::Value = serde_json::from_str(&stdout)
                .map_err(|e| format!("{shown}: stdout is not JSON: {e}"))?;
            let got = doc["series"][0]["wv"][0].as_f64().unwrap_or(f64::NAN);
            let want = haar_level1(n, case.f32);
            if (got - want).abs() > 1e-9 * want.abs() {
                return fail(&format!("level 1 WV {got}, expected {want}"));
            }
        }
        return Ok(());
    }
    if code != 1 && code != 2 {
        return fail(&format!("exit code {code}, expected 1 or 2"));
    }
    if errors.len() != 1 || !errors[0].starts_with("gmwm: error: ") {
        return fail("not exactly one error line");
    }
    let line = errors[0];
    // the line names the file (or standard input) or a flag
    let flag_named = args
        .iter()
        .filter(|a| a.len() > 3 && *a != &file)
        .any(|a| line.contains(a.split('=').next().unwrap_or(a)))
        || line.contains("model")
        || line.contains("standard output");
    let file_named = match file.as_str() {
        "" => true,
        "-" => line.contains("<stdin>"),
        f => line.contains(f),
    };
    if !file_named && !flag_named {
        return fail("the error line names neither the file nor a flag");
    }
    if let Some(n) = needles.iter().find(|n| match n.strip_prefix("stderr:") {
        Some(n) => !stderr.contains(n),
        None => !line.contains(n.as_str()),
    }) {
        return fail(&format!("{n:?} not in the error line (stderr: on stderr)"));
    }
    // the cause once: no ": X: X" doubling of a cause
    let parts: Vec<&str> = line.split(": ").collect();
    if parts.windows(2).any(|w| w[0] == w[1] && w[0].len() > 3) {
        return fail("a cause repeated");
    }
    if !full && !case.summary && !stdout.is_empty() {
        return fail("partial results on stdout");
    }
    Ok(())
}

#[test]
fn every_bad_input_through_every_command() {
    let cases = manifest();
    let work = tempfile::tempdir().unwrap();
    for entry in std::fs::read_dir(corpus()).unwrap() {
        let entry = entry.unwrap();
        std::fs::copy(entry.path(), work.path().join(entry.file_name())).unwrap();
    }
    std::fs::write(work.path().join("a_regular_file"), b"not a folder\n").unwrap();
    let runs: Vec<(&Case, &str)> = cases
        .iter()
        .flat_map(|c| c.commands.iter().map(move |cmd| (c, cmd.as_str())))
        .collect();
    let next = AtomicUsize::new(0);
    let failures = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some((case, command)) = runs.get(i) else {
                    break;
                };
                if let Err(e) = check(case, command, work.path(), i) {
                    failures
                        .lock()
                        .unwrap()
                        .push(format!("[{}] {e}", case.name));
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    println!(
        "bad-input corpus: {} cases, {} runs, {} failed",
        cases.len(),
        runs.len(),
        failures.len()
    );
    assert!(
        cases.len() >= 80,
        "the corpus has {} cases; issue 15 asks for at least 80",
        cases.len()
    );
    let names: std::collections::HashSet<&str> = cases.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names.len(), cases.len(), "case names are unique");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn the_corpus_files_are_those_gen_py_writes() {
    // every file the manifest names exists (gen.py was run after the manifest was edited)
    for case in manifest() {
        let f = case.file.trim_start_matches("-<");
        let f = f.strip_prefix("@fifo:").unwrap_or(f);
        if !f.starts_with('@') && f != "~" {
            assert!(corpus().join(f).is_file(), "{}: {f} missing", case.name);
        }
    }
}
