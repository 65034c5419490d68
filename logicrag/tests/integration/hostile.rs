//! The hostile inputs of issue 13, one test per row of its table: each runs
//! the real binary under 3 GB of address space (`prlimit --as`) and a 60 s
//! wall-clock limit, and must end in an answer (exit 0) or a clear error
//! (exit 2) — never an abort, a kill, a hang or a file written outside the
//! output folder.
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

const ADDRESS_SPACE: u64 = 3 * 1024 * 1024 * 1024;
const WALL_LIMIT: Duration = Duration::from_secs(60);

/// A scratch directory, removed when dropped.
struct TempDir(PathBuf);

impl TempDir {
    fn new(test: &str) -> TempDir {
        let dir =
            std::env::temp_dir().join(format!("logicrag-hostile-{}-{test}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("temp dir");
        TempDir(dir)
    }

    fn file(&self, name: &str, contents: impl AsRef<[u8]>) -> PathBuf {
        let path = self.0.join(name);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).expect("temp subdir");
        }
        std::fs::write(&path, contents).expect("temp file");
        path
    }

    fn fifo(&self, name: &str) -> PathBuf {
        let path = self.0.join(name);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).expect("temp subdir");
        }
        let made = Command::new("mkfifo")
            .arg(&path)
            .status()
            .map(|s| s.success())
            .unwrap_or(false);
        assert!(made, "mkfifo (coreutils) makes the test's FIFO");
        path
    }

    fn arg(&self, name: &str) -> String {
        self.0
            .join(name)
            .to_str()
            .expect("utf-8 temp path")
            .to_string()
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// How a bounded run ended.
struct Bounded {
    output: Output,
    elapsed: Duration,
}

impl Bounded {
    fn code(&self) -> Option<i32> {
        self.output.status.code()
    }

    fn stdout(&self) -> String {
        String::from_utf8_lossy(&self.output.stdout).into_owned()
    }

    fn stderr(&self) -> String {
        String::from_utf8_lossy(&self.output.stderr).into_owned()
    }

    /// Exit 0 or 2 in time; on failure the message shows what happened.
    fn assert_ends_well(&self, what: &str) {
        assert!(
            matches!(self.code(), Some(0) | Some(2)),
            "{what}: ended with {:?} after {:?} (an abort is 134, a kill has no code)\nstdout: {}\nstderr: {}",
            self.output.status,
            self.elapsed,
            tail(&self.stdout()),
            tail(&self.stderr())
        );
        assert!(self.elapsed < WALL_LIMIT, "{what}: took {:?}", self.elapsed);
    }

    fn assert_error(&self, what: &str, needle: &str) {
        self.assert_ends_well(what);
        assert_eq!(self.code(), Some(2), "{what}: {}", tail(&self.stderr()));
        assert!(
            self.stderr().contains(needle),
            "{what}: the error should say {needle:?}: {}",
            tail(&self.stderr())
        );
        // Errors are read by people: no Debug dumps, no walls of text.
        assert!(
            !self.stderr().contains(" { ") && self.stderr().len() < 4_000,
            "{what}: {}",
            tail(&self.stderr())
        );
    }
}

fn tail(s: &str) -> String {
    let chars: Vec<char> = s.chars().collect();
    let start = chars.len().saturating_sub(1_500);
    chars[start..].iter().collect()
}

/// Runs `logicrag ARGS` under the address-space limit, feeding `stdin`, and
/// kills it when the wall limit passes (a hang then shows as a kill).
fn bounded(args: &[&str], stdin: Option<&str>) -> Bounded {
    let prlimit = Path::new("/usr/bin/prlimit");
    assert!(
        prlimit.exists(),
        "prlimit (util-linux) enforces the 3 GB address space of these tests"
    );
    let mut cmd = Command::new(prlimit);
    cmd.arg(format!("--as={ADDRESS_SPACE}"))
        .arg(env!("CARGO_BIN_EXE_logicrag"))
        .args(args)
        .stdin(if stdin.is_some() {
            Stdio::piped()
        } else {
            Stdio::null()
        })
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let start = Instant::now();
    let mut child = cmd.spawn().expect("prlimit runs the logicrag binary");
    if let Some(text) = stdin {
        let mut pipe = child.stdin.take().expect("piped stdin");
        pipe.write_all(text.as_bytes()).expect("write stdin");
    }
    let output = wait_bounded(child, start);
    Bounded {
        output,
        elapsed: start.elapsed(),
    }
}

fn wait_bounded(mut child: Child, start: Instant) -> Output {
    // Read the pipes on threads so a chatty child cannot block on a full pipe.
    let mut out = child.stdout.take().expect("piped stdout");
    let mut err = child.stderr.take().expect("piped stderr");
    let out_reader = std::thread::spawn(move || {
        let mut buf = Vec::new();
        let _ = std::io::Read::read_to_end(&mut out, &mut buf);
        buf
    });
    let err_reader = std::thread::spawn(move || {
        let mut buf = Vec::new();
        let _ = std::io::Read::read_to_end(&mut err, &mut buf);
        buf
    });
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait for logicrag") {
            break status;
        }
        if start.elapsed() > WALL_LIMIT {
            let _ = child.kill();
            break child.wait().expect("reap logicrag");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    Output {
        status,
        stdout: out_reader.join().unwrap_or_default(),
        stderr: err_reader.join().unwrap_or_default(),
    }
}

/// Every file under `dir`, so a test can show nothing was written elsewhere.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else {
                found.push(p);
            }
        }
    }
    found.sort();
    found
}

const FOUR_FACTS: &str = "Vehicles(car_1)\nVehicles(car_2)\nVehicles(car_3)\nVehicles(car_4)\n";

fn scenario(name: &str, frames: u64, agents: usize) -> String {
    let mut s = format!("name: {name}\nframes: {frames}\nfps: 10\nego: {{speed: 8}}\n");
    if agents > 0 {
        s.push_str("agents:\n");
        for i in 0..agents {
            s.push_str(&format!(
                "  - {{id: {}, class: Vehicles, type: Car, color: White, start: [1.75, {}], speed: 5}}\n",
                i + 1,
                10 + i
            ));
        }
    }
    s
}

#[test]
fn row_01_a_twelve_atom_query_over_four_facts_stops_at_the_answer_limit() {
    let tmp = TempDir::new("atoms");
    let facts = tmp.file("w0.facts", FOUR_FACTS);
    let src = format!("facts:{}", facts.display());
    let vehicles = |n: usize| {
        (0..n)
            .map(|i| format!("Vehicles(v{i})"))
            .collect::<Vec<_>>()
            .join(" ^ ")
    };
    let r = bounded(&["ask", "--source", &src, &vehicles(12)], None);
    r.assert_ends_well("12 atoms");
    // The answers found before the limit, saying it stopped there.
    assert!(
        r.stdout().contains("YES (at least 100000 answers)")
            && r.stdout().contains("the run stopped at its answers limit"),
        "{}",
        r.stdout()
    );
    // A one-line --tsv batch of `n` atoms.
    let tsv = |n: usize, extra: &[&str]| {
        let batch = tmp.file(&format!("q{n}.tsv"), format!("w0\t{}\n", vehicles(n)));
        let batch = batch.to_str().expect("utf-8").to_string();
        let mut args = vec!["ask", "--source", &src, "--queries", &batch, "--tsv"];
        args.extend_from_slice(extra);
        bounded(&args, None)
    };
    // With --tsv only the count is wanted (11 atoms took 2.5 GB): it is
    // counted without keeping any answer, 4^11 of them.
    let r = tsv(11, &[]);
    r.assert_ends_well("11 atoms, --tsv");
    assert_eq!(r.stdout().trim(), format!("w0\t0\tyes\t{}", 4u64.pow(11)));
    // Beyond the counting budget (max answers × 1000) it stops there: the
    // line has the count so far, stderr says it is a lower bound.
    let r = tsv(14, &["--max-answers", "1000"]);
    r.assert_ends_well("14 atoms, --tsv");
    assert_eq!(r.stdout().trim(), "w0\t0\tyes\t1000000");
    assert!(
        r.stderr().contains(
            "window w0, query 0: the run stopped at its answers limit: the count 1000000 is a lower bound"
        ),
        "{}",
        r.stderr()
    );
}

#[test]
fn row_02_a_scenario_of_a_million_frames_is_refused() {
    let tmp = TempDir::new("frames");
    let file = tmp.file("long.yaml", scenario("long", 1_000_000, 3));
    let src = format!("sim:{}", file.display());
    let r = bounded(&["ask", "--source", &src, "Moving(x)"], None);
    r.assert_error("frames: 1000000", "object-frames");
}

#[test]
fn row_03_two_thousand_objects_in_one_kitti_frame_are_refused() {
    let tmp = TempDir::new("kitti");
    tmp.file(
        "calib/0000.txt",
        "P2: 7.215377e+02 0.000000e+00 6.095593e+02 4.485728e+01 0.000000e+00 7.215377e+02 1.728540e+02 2.163791e-01 0.000000e+00 0.000000e+00 1.000000e+00 2.745884e-03\n",
    );
    let mut labels = String::new();
    for id in 0..2_000 {
        let x = -20.0 + (id % 40) as f64;
        let z = 5.0 + (id / 40) as f64;
        labels.push_str(&format!(
            "0 {id} Car 0 0 -1.57 100.0 150.0 200.0 250.0 1.5 1.6 3.9 {x:.1} 1.7 {z:.1} -1.57\n"
        ));
    }
    tmp.file("label_02/0000.txt", &labels);
    let src = format!("kitti:{}", tmp.0.display());
    let r = bounded(
        &["ask", "--source", &src, "--sequence", "0000", "Moving(x)"],
        None,
    );
    r.assert_error("2000 objects in a frame", "label_02/0000.txt");
    assert!(r.stderr().contains("256"), "{}", r.stderr());
}

#[test]
fn row_04_a_scenario_name_cannot_write_outside_the_output_folder() {
    let tmp = TempDir::new("escape");
    let file = tmp.file("hostile.yaml", scenario("../../x", 20, 2));
    let out_dir = tmp.0.join("a/b/out");
    std::fs::create_dir_all(&out_dir).expect("out dir");
    let before = files_under(&tmp.0);
    let r = bounded(
        &[
            "simulate",
            file.to_str().expect("utf-8"),
            "--out",
            out_dir.to_str().expect("utf-8"),
        ],
        None,
    );
    r.assert_ends_well("name ../../x");
    let after: Vec<PathBuf> = files_under(&tmp.0)
        .into_iter()
        .filter(|p| !before.contains(p))
        .collect();
    assert!(
        after.iter().all(|p| p.starts_with(&out_dir)),
        "written outside --out: {after:?}"
    );
    assert_eq!(r.code(), Some(2), "{}", r.stderr());
}

#[test]
fn row_05_ten_thousand_chained_implications_end_in_an_error() {
    let tmp = TempDir::new("chain");
    let chain = (0..10_000)
        .map(|i| format!("P{i}(x)"))
        .collect::<Vec<_>>()
        .join(" ==> ");
    let pad = tmp.file(
        "pad.yaml",
        format!(
            "atomic_predicates:\n  tracker:\n    - Vehicles(x)\nderived_predicates:\n  - name: Deep\n    logic: \"∀x : {chain} ==> Deep(x)\"\n"
        ),
    );
    let r = bounded(&["lint", pad.to_str().expect("utf-8")], None);
    r.assert_ends_well("lint of a 10,000-deep rule");
    // lint reports on stdout; the 133 KB line is shown as an excerpt.
    assert_eq!(r.code(), Some(2), "{}", r.stderr());
    assert!(
        r.stdout().contains("pad.yaml:6:") && r.stdout().contains("nested more than 200 levels"),
        "{}",
        tail(&r.stdout())
    );
    assert!(r.stdout().len() < 2_000, "{}", tail(&r.stdout()));
    let batch = tmp.file("q.tsv", format!("urban_crossing_000000\t{chain}\n"));
    let r = bounded(
        &["ask", "--queries", batch.to_str().expect("utf-8"), "--tsv"],
        None,
    );
    r.assert_ends_well("a 10,000-deep --queries line");
}

#[test]
fn row_06_a_huge_savgol_window_is_refused_with_its_range() {
    let tmp = TempDir::new("savgol");
    let cfg = tmp.file("c.yaml", "savgol_window: 1000000001\n");
    let r = bounded(
        &["ask", "--config", cfg.to_str().expect("utf-8"), "Moving(x)"],
        None,
    );
    r.assert_error("savgol_window 1000000001", "c.yaml");
    assert!(r.stderr().contains("101"), "{}", r.stderr());
}

#[test]
fn row_07_fifos_as_labels_frames_logicpad_or_repl_load_do_not_hang() {
    let tmp = TempDir::new("fifo");
    // A KITTI label file.
    tmp.file(
        "kitti/calib/0000.txt",
        "P2: 721.5 0 609.6 0 0 721.5 172.9 0 0 0 1 0\n",
    );
    tmp.fifo("kitti/label_02/0000.txt");
    let src = format!("kitti:{}", tmp.arg("kitti"));
    let r = bounded(
        &["ask", "--source", &src, "--sequence", "0000", "Moving(x)"],
        None,
    );
    r.assert_error("a FIFO label file", "not a regular file");
    // A frame under frames:DIR.
    tmp.fifo("frames/000000.png");
    let src = format!("frames:{}", tmp.arg("frames"));
    let models = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../perception/models/nanodet-m-416-coco.yaml"
    );
    let r = bounded(
        &["ask", "--source", &src, "--models", models, "Moving(x)"],
        None,
    );
    r.assert_error("a FIFO frame", "not a regular file");
    // A LogicPad.
    let pad = tmp.fifo("pad.yaml");
    let r = bounded(
        &[
            "ask",
            "--logicpad",
            pad.to_str().expect("utf-8"),
            "Moving(x)",
        ],
        None,
    );
    r.assert_error("a FIFO LogicPad", "not a regular file");
    // REPL :load.
    let r = bounded(
        &["repl"],
        Some(&format!(":load {}\nMoving(x)\n", pad.display())),
    );
    r.assert_ends_well("REPL :load of a FIFO");
    assert!(
        (r.stdout() + &r.stderr()).contains("not a regular file"),
        "{}{}",
        r.stdout(),
        r.stderr()
    );
}

/// A PNG of `width`×`height` black pixels, compressed: a few hundred KB
/// that would decode to gigabytes.
fn huge_png(width: u32, height: u32) -> Vec<u8> {
    use image::ImageEncoder;
    // Encode row by row through the png encoder's writer would need the
    // `png` crate; a 1×1 image with its IHDR rewritten exercises the same
    // header check without spending seconds compressing zeros.
    let mut small = Vec::new();
    image::codecs::png::PngEncoder::new(&mut small)
        .write_image(&[0, 0, 0], 1, 1, image::ExtendedColorType::Rgb8)
        .expect("encode a 1×1 PNG");
    small[16..20].copy_from_slice(&width.to_be_bytes());
    small[20..24].copy_from_slice(&height.to_be_bytes());
    let crc = crc32(&small[12..29]);
    small[29..33].copy_from_slice(&crc.to_be_bytes());
    small
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut c = 0xffff_ffffu32;
    for &b in bytes {
        c ^= u32::from(b);
        for _ in 0..8 {
            c = if c & 1 != 0 {
                0xedb8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}

#[test]
fn row_08_a_20000_by_20000_png_is_refused_from_its_header() {
    let tmp = TempDir::new("png");
    tmp.file("frames/000000.png", huge_png(20_000, 20_000));
    let src = format!("frames:{}", tmp.arg("frames"));
    let models = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../perception/models/nanodet-m-416-coco.yaml"
    );
    let r = bounded(
        &["ask", "--source", &src, "--models", models, "Moving(x)"],
        None,
    );
    r.assert_error("a 20000×20000 PNG", "20000×20000");
    assert!(r.stderr().contains("000000.png"), "{}", r.stderr());
}

#[test]
fn row_09_a_hundred_thousand_fact_files_are_refused() {
    let tmp = TempDir::new("many");
    let dir = tmp.0.join("kb");
    std::fs::create_dir_all(&dir).expect("kb dir");
    for i in 0..100_000 {
        std::fs::write(
            dir.join(format!("w{i:06}.facts")),
            "Vehicles(car_1)\nMoving(car_1)\n",
        )
        .expect("fact file");
    }
    let src = format!("facts:{}", dir.display());
    let r = bounded(&["ask", "--source", &src, "Moving(x)"], None);
    r.assert_error("100,000 fact files", "20000");
}

#[test]
fn row_10_a_chain_of_twenty_thousand_disequalities_is_answered() {
    let tmp = TempDir::new("neq");
    let chain: Vec<String> = (0..20_000).map(|i| format!("x != c{i}")).collect();
    let q = tmp.file(
        "q.tsv",
        format!("urban_crossing_000020\tMoving(x) ^ {}\n", chain.join(" ^ ")),
    );
    let r = bounded(
        &["ask", "--queries", q.to_str().expect("utf-8"), "--tsv"],
        None,
    );
    r.assert_ends_well("20,000 disequalities");
    assert_eq!(r.code(), Some(0));
    // Moving: the sedan, the pedestrian and the ego (braking from 5.4 to
    // 2.9 m/s over frames 20-29).
    assert_eq!(r.stdout().trim(), "urban_crossing_000020\t0\tyes\t3");
}

#[test]
fn row_11_a_scenario_of_two_thousand_agents_is_refused() {
    let tmp = TempDir::new("agents");
    let file = tmp.file("crowd.yaml", scenario("crowd", 20, 2_000));
    let src = format!("sim:{}", file.display());
    let r = bounded(&["ask", "--source", &src, "Moving(x)"], None);
    r.assert_error("2,000 agents", "2000 objects");
    assert!(r.stderr().contains("256"), "{}", r.stderr());
}
