//! The page of `logicrag serve` in a real browser: headless Chromium (the
//! Debian package `chromium`, installed by `.ci/run`) opens a shareable
//! link `/?window=…&q=…`, runs the page's script against the live server,
//! and the rendered DOM must show the answer, its bindings, its proof and
//! pictures (a loaded frame, the bird's-eye SVG). A screenshot is taken
//! too; with `LOGICRAG_UPDATE_DOCS=1` it replaces `docs/serve.png`.
//!
//! Without Chromium these tests fail and say how to install it: a browser
//! test that skips itself would pass having checked nothing.

use crate::common::Served;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The longest a page may take to load and answer, in the browser's
/// virtual time (network waits do not count against it).
const VIRTUAL_TIME_MS: u32 = 15_000;
/// The longest Chromium may run, in wall time.
const BROWSER_TIMEOUT: Duration = Duration::from_secs(120);

/// Chromium: `$LOGICRAG_CHROMIUM`, else `chromium` on the PATH.
fn chromium() -> PathBuf {
    if let Some(p) = std::env::var_os("LOGICRAG_CHROMIUM") {
        return PathBuf::from(p);
    }
    let found = std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|d| d.join("chromium"))
            .find(|p| p.is_file())
    });
    match found {
        Some(p) => p,
        None => panic!(
            "the browser tests need Chromium: `apt-get install -y --no-install-recommends chromium` \
             (.ci/run does this), or set LOGICRAG_CHROMIUM to a Chromium binary"
        ),
    }
}

/// Runs headless Chromium on `url` with `extra` arguments and returns its
/// stdout; fails the test when it cannot run or runs too long.
fn run_chromium(url: &str, extra: &[String], profile: &Path) -> String {
    let mut child = Command::new(chromium())
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--virtual-time-budget={VIRTUAL_TIME_MS}"))
        .args(extra)
        .arg(url)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("chromium starts");
    let mut stdout = child.stdout.take().expect("piped");
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = std::io::Read::read_to_string(&mut stdout, &mut s);
        s
    });
    let start = Instant::now();
    loop {
        match child.try_wait().expect("wait") {
            Some(status) => {
                assert!(status.success(), "chromium failed: {status}");
                break;
            }
            None if start.elapsed() > BROWSER_TIMEOUT => {
                let _ = child.kill();
                let _ = child.wait();
                panic!("chromium ran longer than {BROWSER_TIMEOUT:?} on {url}");
            }
            None => std::thread::sleep(Duration::from_millis(100)),
        }
    }
    reader.join().expect("the reader thread")
}

/// A scratch directory under the target directory, emptied first.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("browser-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// The element that starts with `open` (e.g. `<table class="bindings"`)
/// up to its closing `</tag>`: enough structure for a rendered-DOM check
/// without a parser.
fn element<'a>(dom: &'a str, open: &str, tag: &str) -> &'a str {
    let Some(start) = dom.find(open) else {
        panic!("the page has no `{open}`:\n{}", &dom[..dom.len().min(4000)]);
    };
    let rest = &dom[start..];
    let end = rest
        .find(&format!("</{tag}>"))
        .map_or(rest.len(), |e| e + tag.len() + 3);
    &rest[..end]
}

const QUESTION_URL: &str = "/?window=urban_crossing_000020&q=Is%20the%20pedestrian%20walking%3F";

#[test]
fn a_shared_link_shows_the_answer_its_bindings_and_pictures() {
    let s = Served::start(&["--source", "sim:urban_crossing"], &[]);
    let dir = scratch("answer");
    let dom = run_chromium(
        &s.at(QUESTION_URL),
        &["--dump-dom".to_string()],
        &dir.join("profile"),
    );
    assert!(
        dom.contains("data-state=\"answered\""),
        "the page did not finish answering:\n{}",
        &dom[..dom.len().min(4000)]
    );
    let headline = element(
        &dom,
        "<div class=\"headline\" id=\"answer-headline\"",
        "div",
    );
    assert!(headline.contains("yes — in frames 20–29"), "{headline}");
    let bindings = element(&dom, "<table class=\"bindings\"", "table");
    assert!(
        bindings.contains("<th>x</th>") && bindings.contains("<code>pedestrian_5</code>"),
        "{bindings}"
    );
    let proof = element(&dom, "<ul class=\"proof\"", "ul");
    assert!(proof.contains("Walk(pedestrian_5)"), "{proof}");
    assert!(proof.contains("rule, line"), "{proof}");
    // Pictures: the frame as loaded by the browser, its boxes, the BEV.
    let img = element(&dom, "<img id=\"frame-img\"", "img");
    assert!(
        img.contains("/api/frame?window=urban_crossing_000020&amp;index=0"),
        "{img}"
    );
    assert!(
        img.contains("data-loaded=\"true\""),
        "the frame was not loaded: {img}"
    );
    let boxes = element(&dom, "<svg viewBox=\"0 0 1242 375\"", "svg");
    assert!(boxes.contains("pedestrian_5 #5"), "{boxes}");
    let bev = element(&dom, "<svg viewBox=\"0 0 520 460\" id=\"bev\"", "svg");
    assert!(
        bev.contains("<polyline") && bev.contains("pedestrian_5 #5"),
        "{bev}"
    );
    // The context and the facts with their provenance.
    assert!(dom.contains("The answer is yes: 1 binding satisfies the query."));
    assert!(dom.contains("class=\"hit\"><td><code>Moving(pedestrian_5)</code></td><td>sim:urban_crossing window 2, frames 20–29"));
    // The question asked is the link's.
    assert!(dom.contains("“Is the pedestrian walking?” → query"));

    // And the picture a person sees.
    let shot = dir.join("serve.png");
    run_chromium(
        &s.at(QUESTION_URL),
        &[
            format!("--screenshot={}", shot.display()),
            "--window-size=1280,1600".to_string(),
        ],
        &dir.join("profile-shot"),
    );
    let img = image::open(&shot).expect("a screenshot").to_rgb8();
    assert_eq!((img.width(), img.height()), (1280, 1600));
    let colours: std::collections::HashSet<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    assert!(
        colours.len() > 500,
        "a blank page: {} colours",
        colours.len()
    );
    if std::env::var_os("LOGICRAG_UPDATE_DOCS").is_some() {
        let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/serve.png");
        std::fs::copy(&shot, &docs).expect("docs/serve.png");
    }
}

/// Issue 22 item 3: on a noisy source the page says how sure each window's
/// answer is, and C2 says it in words.
#[test]
fn on_a_noisy_source_the_page_says_how_sure_each_answer_is() {
    let s = Served::start(
        &["--source", "sim:urban_crossing@3", "--noise", "high"],
        &[],
    );
    let dir = scratch("probability");
    let dom = run_chromium(
        &s.at("/?window=urban_crossing_000000&q=Is%20the%20red%20car%20stopped%3F"),
        &["--dump-dom".to_string()],
        &dir.join("profile"),
    );
    assert!(
        dom.contains("data-state=\"answered\""),
        "the page did not finish answering:\n{}",
        &dom[..dom.len().min(4000)]
    );
    assert!(
        dom.contains("· 1 answer · probability 0."),
        "no probability beside the answer:\n{}",
        &dom[..dom.len().min(6000)]
    );
    // Below context::PROBABLY_BELOW the verdict also says "probably".
    assert!(
        dom.contains("The answer is yes, with probability 0.")
            || dom.contains("The answer is probably yes, with probability 0."),
        "C2 does not say it"
    );
}

#[test]
fn behind_a_token_the_page_sends_it_with_every_request() {
    let token = "page-Token-7";
    let s = Served::start(&["--source", "sim:urban_crossing", "--token", token], &[]);
    let dir = scratch("token");
    let dom = run_chromium(
        &s.at(&format!("{QUESTION_URL}&access_token={token}")),
        &["--dump-dom".to_string()],
        &dir.join("profile"),
    );
    assert!(
        dom.contains("data-state=\"answered\""),
        "{}",
        &dom[..dom.len().min(4000)]
    );
    assert!(dom.contains("yes — in frames 20–29"));
    let img = element(&dom, "<img id=\"frame-img\"", "img");
    assert!(
        img.contains("data-loaded=\"true\""),
        "the frame was not loaded: {img}"
    );
    // Without the token the browser gets the JSON refusal, not the page.
    let dom = run_chromium(
        &s.at(QUESTION_URL),
        &["--dump-dom".to_string()],
        &dir.join("profile-2"),
    );
    assert!(dom.contains("this server needs its token"), "{dom}");
}

/// `kitti:` of the shared KITTI tracking data, sequence 0001 (pictures of
/// frames 10, 15 and 20 only), or None where `../shared` is absent.
fn kitti_0001() -> Option<String> {
    let shared = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared");
    if !shared.join("data/kitti-tracking/image_02/0001").is_dir() {
        eprintln!("SKIPPED: ../shared is not present");
        return None;
    }
    Some(format!(
        "kitti:{}",
        shared.join("data/kitti-tracking").display()
    ))
}

/// An Argoverse 2 log's window: the bird's-eye view draws the map (lanes
/// named as in the facts, crosswalks) and every object, and the header says
/// how many inputs the source skipped. `None` where `../shared` is absent
/// (then fails unless `LOGICRAG_SKIP_MISSING` is set).
#[test]
fn an_av2_window_draws_its_map_under_the_tracks() {
    let log = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/data/av2/scenario_mining/3b3570b4-7b0b-3268-a571-b0889dbf40b6");
    if !log.is_dir() {
        assert!(
            std::env::var_os("LOGICRAG_SKIP_MISSING").is_some(),
            "{} is not present (set LOGICRAG_SKIP_MISSING=1 to skip tests whose inputs are absent)",
            log.display()
        );
        return;
    }
    let src = format!("av2:{}", log.display());
    let s = Served::start(&["--source", &src, "--frames", "0-9"], &[]);
    let dir = scratch("av2-map");
    let dom = run_chromium(
        &s.at("/?window=3b3570b4-7b0b-3268-a571-b0889dbf40b6_000000"),
        &["--dump-dom".to_string()],
        &dir.join("profile"),
    );
    assert!(
        dom.contains("data-state=\"ready\""),
        "{}",
        &dom[..dom.len().min(4000)]
    );
    let map = element(&dom, "<g class=\"map\"", "g");
    assert!(map.contains("fill=\"#ffe27a\""), "no crosswalk drawn");
    assert!(
        map.contains("<title>lane_"),
        "no lane named as in the facts"
    );
    assert!(map.matches("<polygon").count() > 20);
    assert!(
        dom.contains("157 inputs skipped"),
        "the skipped rows are not said"
    );
    assert!(dom.matches("data-track=").count() > 30);
    // No pixel boxes: the frame pane says where the objects are.
    assert!(dom.contains("(a 360° log): see the bird's-eye view"));
}

#[test]
fn a_kitti_window_without_pictures_shows_a_placeholder_not_a_broken_image() {
    let Some(kitti) = kitti_0001() else { return };
    let s = Served::start(&["--source", &kitti, "--sequence", "0001"], &[]);
    let dir = scratch("kitti-noimg");
    // Frames 0–9 have no picture at all.
    let dom = run_chromium(
        &s.at("/?window=0001_000000"),
        &["--dump-dom".to_string()],
        &dir.join("profile"),
    );
    assert!(
        dom.contains("data-state=\"ready\""),
        "{}",
        &dom[..dom.len().min(4000)]
    );
    let view = element(&dom, "<div id=\"frame-view\"", "div");
    assert!(!view.contains("<img"), "an image without a picture: {view}");
    let placeholder = element(
        &dom,
        "<div class=\"noimg placeholder\" id=\"frame-placeholder\"",
        "div",
    );
    assert!(
        placeholder.contains("no camera image for frames 0–9"),
        "{placeholder}"
    );
    let strip = element(&dom, "<div id=\"frame-strip\"", "div");
    assert!(!strip.contains("<img"), "{strip}");
    // The boxes are still drawn over the placeholder.
    assert!(dom.contains("id=\"frame-boxes\""));

    // Frames 10–19: frame 10 has a picture (loaded), 11 has none; the
    // link keeps the frame.
    let dom = run_chromium(
        &s.at("/?window=0001_000010&frame=1"),
        &["--dump-dom".to_string()],
        &dir.join("profile-2"),
    );
    let placeholder = element(
        &dom,
        "<div class=\"noimg placeholder\" id=\"frame-placeholder\"",
        "div",
    );
    assert!(
        placeholder.contains("no camera image for frames 11–14, 16–19"),
        "{placeholder}"
    );
    let strip = element(&dom, "<div id=\"frame-strip\"", "div");
    assert_eq!(strip.matches("<img").count(), 2, "{strip}");
    let dom = run_chromium(
        &s.at("/?window=0001_000010"),
        &["--dump-dom".to_string()],
        &dir.join("profile-3"),
    );
    let img = element(&dom, "<img id=\"frame-img\"", "img");
    assert!(img.contains("data-loaded=\"true\""), "{img}");

    // An unknown window in a link says so.
    let dom = run_chromium(
        &s.at("/?window=0001_999999&q=Is%20there%20a%20car%3F"),
        &["--dump-dom".to_string()],
        &dir.join("profile-4"),
    );
    let notice = element(&dom, "<div id=\"notice\"", "div");
    assert!(
        notice.contains("this server has no window “0001_999999”"),
        "{notice}"
    );
}

#[test]
fn at_700_pixels_the_ask_button_stays_on_screen() {
    let Some(kitti) = kitti_0001() else { return };
    let s = Served::start(&["--source", &kitti, "--sequence", "0001"], &[]);
    let dir = scratch("narrow");
    let shot = dir.join("narrow.png");
    run_chromium(
        &s.at("/?window=0001_000010"),
        &[
            format!("--screenshot={}", shot.display()),
            "--window-size=700,900".to_string(),
            "--force-device-scale-factor=1".to_string(),
        ],
        &dir.join("profile"),
    );
    let img = image::open(&shot).expect("a screenshot").to_rgb8();
    assert_eq!((img.width(), img.height()), (700, 900));
    // The header is the rows from the top in the page's accent colour at
    // its left edge; the Ask button is the button colour inside it.
    let header = (0..img.height())
        .take_while(|&y| img.get_pixel(2, y).0 == [0x1f, 0x4e, 0x79])
        .count() as u32;
    assert!(header > 20, "no header: {header} rows");
    let button: Vec<(u32, u32)> = (0..header)
        .flat_map(|y| (0..img.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| img.get_pixel(x, y).0 == [0xf2, 0xa9, 0x3b])
        .collect();
    assert!(
        button.len() > 400,
        "no Ask button in the header: {} pixels",
        button.len()
    );
    let (x0, x1) = button
        .iter()
        .fold((u32::MAX, 0), |(a, b), &(x, _)| (a.min(x), b.max(x)));
    assert!(
        x0 > 0 && x1 < img.width() - 1,
        "the Ask button ({x0}–{x1}) is cut by the 700 px viewport"
    );
}
