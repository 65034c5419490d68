//! A bounded load test of a running `logicrag serve` (loopback only): N
//! keep-alive clients post one request body for D seconds (at most 60) and
//! the requests/s, p50 and p99 are printed; with `--pid` the server's
//! resident memory (now and its peak) is printed too.
//!
//! ```text
//! cargo run --release --example serve_load -- --url http://127.0.0.1:8080 \
//!     --path /api/ask --body '{"question":"Is the pedestrian walking?"}' \
//!     --clients 16 --seconds 10 --pid $(pgrep -n logicrag)
//! ```
//!
//! `--once` sends the body a single time and prints the status, the
//! response's size and the time it took (the amplification check of
//! docs/benchmarks.md). Plain HTTP/1.1 over `std::net`, so that the client
//! costs little next to the server it measures.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};

/// The longest run allowed: the script is meant for CI-sized checks.
const MAX_SECONDS: u64 = 60;

struct Args {
    addr: SocketAddr,
    path: String,
    body: String,
    clients: usize,
    seconds: u64,
    pid: Option<u32>,
    once: bool,
    token: Option<String>,
}

fn parse_args() -> Result<Args, String> {
    let mut a = Args {
        addr: "127.0.0.1:8080".parse().map_err(|e| format!("{e}"))?,
        path: "/api/ask".into(),
        body: r#"{"question":"Is the pedestrian walking?"}"#.into(),
        clients: 16,
        seconds: 10,
        pid: None,
        once: false,
        token: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = || it.next().ok_or_else(|| format!("{flag} needs a value"));
        match flag.as_str() {
            "--url" => {
                let v = value()?;
                let hostport = v.trim_start_matches("http://").trim_end_matches('/');
                a.addr = hostport
                    .parse()
                    .map_err(|e| format!("--url {v}: {e} (give http://IP:PORT)"))?;
            }
            "--path" => a.path = value()?,
            "--body" => a.body = value()?,
            "--clients" => a.clients = value()?.parse().map_err(|e| format!("--clients: {e}"))?,
            "--seconds" => a.seconds = value()?.parse().map_err(|e| format!("--seconds: {e}"))?,
            "--pid" => a.pid = Some(value()?.parse().map_err(|e| format!("--pid: {e}"))?),
            "--token" => a.token = Some(value()?),
            "--once" => a.once = true,
            other => return Err(format!("unknown flag {other}")),
        }
    }
    if !a.addr.ip().is_loopback() {
        return Err(format!(
            "{} is not loopback: this load test only runs on loopback",
            a.addr
        ));
    }
    if a.seconds == 0 || a.seconds > MAX_SECONDS {
        return Err(format!("--seconds must be 1 to {MAX_SECONDS}"));
    }
    if a.clients == 0 {
        return Err("--clients must be at least 1".into());
    }
    Ok(a)
}

/// The request's bytes.
fn request(a: &Args) -> Vec<u8> {
    let auth = a
        .token
        .as_ref()
        .map(|t| format!("Authorization: Bearer {t}\r\n"))
        .unwrap_or_default();
    format!(
        "POST {} HTTP/1.1\r\nHost: {}\r\nContent-Type: application/json\r\n{auth}Content-Length: {}\r\n\r\n{}",
        a.path,
        a.addr,
        a.body.len(),
        a.body
    )
    .into_bytes()
}

/// Reads one response; returns its status and body size.
fn read_response(r: &mut BufReader<TcpStream>) -> std::io::Result<(u16, usize)> {
    let mut line = String::new();
    if r.read_line(&mut line)? == 0 {
        return Err(std::io::Error::other("the server closed the connection"));
    }
    let status: u16 = line
        .split_whitespace()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let (mut length, mut chunked) = (None, false);
    loop {
        let mut h = String::new();
        if r.read_line(&mut h)? == 0 || h == "\r\n" {
            break;
        }
        let (name, value) = h.split_once(':').unwrap_or((&h, ""));
        match name.trim().to_ascii_lowercase().as_str() {
            "content-length" => length = value.trim().parse::<usize>().ok(),
            "transfer-encoding" => chunked = value.to_ascii_lowercase().contains("chunked"),
            _ => {}
        }
    }
    let mut size = 0;
    if chunked {
        loop {
            let mut l = String::new();
            r.read_line(&mut l)?;
            let n = usize::from_str_radix(l.trim(), 16).map_err(std::io::Error::other)?;
            let mut buf = vec![0; n + 2];
            r.read_exact(&mut buf)?;
            size += n;
            if n == 0 {
                break;
            }
        }
    } else if let Some(n) = length {
        let mut buf = vec![0; n];
        r.read_exact(&mut buf)?;
        size = n;
    }
    Ok((status, size))
}

/// The resident memory of `pid` (now, peak), in MB.
fn rss(pid: u32) -> Option<(f64, f64)> {
    let s = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let field = |name: &str| -> Option<f64> {
        let line = s.lines().find(|l| l.starts_with(name))?;
        let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kb / 1024.0)
    };
    Some((field("VmRSS:")?, field("VmHWM:")?))
}

fn percentile(sorted: &[Duration], p: f64) -> Duration {
    if sorted.is_empty() {
        return Duration::ZERO;
    }
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}

fn main() -> Result<(), String> {
    let a = parse_args()?;
    let req = request(&a);
    if a.once {
        let t = Instant::now();
        let stream = TcpStream::connect(a.addr).map_err(|e| e.to_string())?;
        stream
            .set_read_timeout(Some(Duration::from_secs(120)))
            .map_err(|e| e.to_string())?;
        (&stream).write_all(&req).map_err(|e| e.to_string())?;
        let (status, size) =
            read_response(&mut BufReader::new(stream)).map_err(|e| e.to_string())?;
        println!(
            "status {status}, {size} bytes in {:.1} ms",
            t.elapsed().as_secs_f64() * 1e3
        );
        if let Some((now, peak)) = a.pid.and_then(rss) {
            println!("server resident memory {now:.0} MB (peak {peak:.0} MB)");
        }
        return Ok(());
    }
    let deadline = Instant::now() + Duration::from_secs(a.seconds);
    let started = Instant::now();
    let handles: Vec<_> = (0..a.clients)
        .map(|_| {
            let (req, addr) = (req.clone(), a.addr);
            std::thread::spawn(move || -> (Vec<Duration>, usize) {
                let mut lat = Vec::new();
                let mut errors = 0;
                let mut conn: Option<BufReader<TcpStream>> = None;
                while Instant::now() < deadline {
                    let r = match conn.as_mut() {
                        Some(r) => r,
                        None => match TcpStream::connect(addr) {
                            Ok(s) => {
                                let _ = s.set_read_timeout(Some(Duration::from_secs(30)));
                                conn.insert(BufReader::new(s))
                            }
                            Err(_) => {
                                errors += 1;
                                std::thread::sleep(Duration::from_millis(10));
                                continue;
                            }
                        },
                    };
                    let t = Instant::now();
                    let ok = r.get_mut().write_all(&req).is_ok()
                        && matches!(read_response(r), Ok((200, _)));
                    if ok {
                        lat.push(t.elapsed());
                    } else {
                        errors += 1;
                        conn = None;
                    }
                }
                (lat, errors)
            })
        })
        .collect();
    let mut all = Vec::new();
    let mut errors = 0;
    for h in handles {
        let (l, e) = h.join().map_err(|_| "a client thread panicked")?;
        all.extend(l);
        errors += e;
    }
    let secs = started.elapsed().as_secs_f64();
    all.sort();
    println!(
        "{} {}: {} clients, {:.1} s: {} requests ({:.0}/s), {errors} errors, p50 {:.2} ms, p99 {:.2} ms",
        a.addr,
        a.path,
        a.clients,
        secs,
        all.len(),
        all.len() as f64 / secs,
        percentile(&all, 0.5).as_secs_f64() * 1e3,
        percentile(&all, 0.99).as_secs_f64() * 1e3
    );
    if let Some((now, peak)) = a.pid.and_then(rss) {
        println!("server resident memory {now:.0} MB (peak {peak:.0} MB)");
    }
    Ok(())
}
