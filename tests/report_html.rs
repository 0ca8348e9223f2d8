//! `report.html` in a real browser: `shadowgraph evaluate --quick` writes it, headless Chromium
//! (Debian's `chromium`, installed by `.ci/run`) loads it from disk with no network, driven
//! over its DevTools protocol on a pipe (`--remote-debugging-pipe`: fds 3 and 4, messages ended
//! by NUL; no port, no extra crate). Asserted: the page loads with no console error, no
//! uncaught exception and no error log entry; it requests nothing but itself and `data:` URIs;
//! every image decodes with a non-zero natural width; the three plots are inline SVG with one
//! marker per configuration, each with a `<title>` tooltip; the verdict lines are at the top
//! (before the plots), name configurations of the table, and the cheapest within 10% of the
//! best penumbra error is the one a direct search of the table finds; every crop caption gives
//! a time; the table sorts when a heading is clicked; a screenshot is not blank. A missing
//! Chromium fails the test, loudly.

use std::io::{BufRead, BufReader, Write};
use std::os::fd::AsRawFd;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use base64::Engine;
use serde_json::{Value, json};

/// How long one DevTools command may take (a software GPU machine under load is slow).
const TIMEOUT: Duration = Duration::from_secs(90);

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("shadowgraph-html-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// `$SHADOWGRAPH_CHROMIUM`, else `chromium` (Debian), `chromium-browser` or `google-chrome` on
/// the PATH; none is a failure.
fn chromium() -> PathBuf {
    if let Some(p) = std::env::var_os("SHADOWGRAPH_CHROMIUM") {
        return p.into();
    }
    let path = std::env::var_os("PATH").unwrap_or_default();
    for name in ["chromium", "chromium-browser", "google-chrome"] {
        for dir in std::env::split_paths(&path) {
            let p = dir.join(name);
            if p.is_file() {
                return p;
            }
        }
    }
    panic!(
        "no Chromium: set SHADOWGRAPH_CHROMIUM or put `chromium` on the PATH (Debian: apt-get \
         install chromium; .ci/run installs it). This test never skips."
    );
}

/// A headless Chromium and one DevTools session on a page.
struct Browser {
    child: Child,
    to: std::io::PipeWriter,
    from: mpsc::Receiver<Value>,
    next: u64,
    /// Events received so far, in order.
    events: Vec<Value>,
    session: String,
    profile: PathBuf,
}

impl Browser {
    fn launch() -> Self {
        let profile = temp_dir("profile");
        std::fs::create_dir_all(&profile).expect("profile dir");
        // Chromium reads commands on fd 3 and writes replies and events on fd 4.
        let (child_read, to) = std::io::pipe().expect("pipe");
        let (from_child, child_write) = std::io::pipe().expect("pipe");
        let (r, w) = (child_read.as_raw_fd(), child_write.as_raw_fd());
        let mut cmd = Command::new(chromium());
        cmd.args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
            "--remote-debugging-pipe",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null());
        // SAFETY: between fork and exec only async-signal-safe calls (fcntl, dup2). Both ends
        // are first copied above fd 9 so that placing one on 3 cannot close the other.
        unsafe {
            cmd.pre_exec(move || {
                let r2 = libc::fcntl(r, libc::F_DUPFD, 10);
                let w2 = libc::fcntl(w, libc::F_DUPFD, 10);
                if r2 < 0 || w2 < 0 || libc::dup2(r2, 3) < 0 || libc::dup2(w2, 4) < 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
        let child = cmd
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start {}: {e}", chromium().display()));
        drop((child_read, child_write));
        let (tx, from) = mpsc::channel();
        std::thread::spawn(move || {
            let mut reader = BufReader::new(from_child);
            loop {
                let mut buf = Vec::new();
                match reader.read_until(0, &mut buf) {
                    Ok(0) | Err(_) => break,
                    Ok(_) => {
                        if buf.last() == Some(&0) {
                            buf.pop();
                        }
                        if let Ok(v) = serde_json::from_slice::<Value>(&buf) {
                            if tx.send(v).is_err() {
                                break;
                            }
                        }
                    }
                }
            }
        });
        let mut b = Self {
            child,
            to,
            from,
            next: 0,
            events: Vec::new(),
            session: String::new(),
            profile,
        };
        let target = b.call(None, "Target.createTarget", json!({"url": "about:blank"}));
        let attached = b.call(
            None,
            "Target.attachToTarget",
            json!({"targetId": target["targetId"], "flatten": true}),
        );
        b.session = attached["sessionId"]
            .as_str()
            .expect("a session id")
            .to_string();
        b
    }

    /// Sends `method` (to the page's session when `page`) and returns its result, keeping the
    /// events that arrive meanwhile.
    fn call(&mut self, session: Option<&str>, method: &str, params: Value) -> Value {
        self.next += 1;
        let id = self.next;
        let mut msg = json!({"id": id, "method": method, "params": params});
        if let Some(s) = session {
            msg["sessionId"] = json!(s);
        }
        let mut bytes = msg.to_string().into_bytes();
        bytes.push(0);
        self.to
            .write_all(&bytes)
            .unwrap_or_else(|e| panic!("{method}: Chromium's pipe closed: {e}"));
        let deadline = Instant::now() + TIMEOUT;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let v = self
                .from
                .recv_timeout(left)
                .unwrap_or_else(|e| panic!("{method}: no answer from Chromium ({e})"));
            if v["id"].as_u64() == Some(id) {
                assert!(v.get("error").is_none(), "{method}: {}", v["error"]);
                return v["result"].clone();
            }
            self.events.push(v);
        }
    }

    fn page(&mut self, method: &str, params: Value) -> Value {
        let session = self.session.clone();
        self.call(Some(&session), method, params)
    }

    /// Waits for the page event `method`.
    fn wait_for(&mut self, method: &str) {
        let deadline = Instant::now() + TIMEOUT;
        while !self.events.iter().any(|e| e["method"] == method) {
            let left = deadline.saturating_duration_since(Instant::now());
            let v = self
                .from
                .recv_timeout(left)
                .unwrap_or_else(|e| panic!("no {method} from Chromium ({e})"));
            self.events.push(v);
        }
    }

    /// The value of a JavaScript expression (promises awaited).
    fn eval(&mut self, expression: &str) -> Value {
        let r = self.page(
            "Runtime.evaluate",
            json!({"expression": expression, "returnByValue": true, "awaitPromise": true}),
        );
        assert!(
            r.get("exceptionDetails").is_none(),
            "{expression}: {}",
            r["exceptionDetails"]
        );
        r["result"]["value"].clone()
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_dir_all(&self.profile);
    }
}

/// What the page did wrong, from the events: console errors, exceptions, error log entries,
/// and requests for anything but the file itself and `data:` URIs.
fn problems(events: &[Value], page: &str) -> Vec<String> {
    let mut out = Vec::new();
    for e in events {
        let p = &e["params"];
        match e["method"].as_str().unwrap_or_default() {
            "Runtime.consoleAPICalled"
                if ["error", "assert"].contains(&p["type"].as_str().unwrap_or("")) =>
            {
                out.push(format!("console {}: {}", p["type"], p["args"]))
            }
            "Runtime.exceptionThrown" => out.push(format!("exception: {}", p["exceptionDetails"])),
            "Log.entryAdded" if p["entry"]["level"] == "error" => {
                out.push(format!("log: {}", p["entry"]["text"]))
            }
            "Network.requestWillBeSent" => {
                let url = p["request"]["url"].as_str().unwrap_or_default();
                if url != page && !url.starts_with("data:") {
                    out.push(format!("request to {url}"));
                }
            }
            _ => {}
        }
    }
    out
}

#[test]
fn report_html_loads_in_headless_chromium() {
    let out = temp_dir("report");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/sphere_on_plane.toml");
    let o = Command::new(env!("CARGO_BIN_EXE_shadowgraph"))
        .arg("evaluate")
        .arg(&scene)
        .args([
            "--quick",
            "--techniques",
            "hard,pcf,pcss,vsm,msm_soft",
            "--out",
        ])
        .arg(&out)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .expect("run shadowgraph");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let html = std::fs::read_to_string(out.join("report.html")).expect("report.html");
    let page = format!("file://{}", out.join("report.html").display());

    let mut b = Browser::launch();
    for domain in ["Page", "Runtime", "Log", "Network"] {
        b.page(&format!("{domain}.enable"), json!({}));
    }
    b.page(
        "Emulation.setDeviceMetricsOverride",
        json!({"width": 1280, "height": 1000, "deviceScaleFactor": 1, "mobile": false}),
    );
    b.page("Page.navigate", json!({"url": page}));
    b.wait_for("Page.loadEventFired");
    // Every image decoded, with a size.
    let decoded = b.eval(
        "Promise.all([...document.images].map(i => i.decode().then(() => true, () => false)))",
    );
    let images = b.eval(
        "[...document.images].map(i => [i.complete, i.naturalWidth, i.naturalHeight, i.alt])",
    );
    let images = images.as_array().expect("an array of images");
    // The overview pair, and per crop the truth's two images and three per configuration.
    assert!(images.len() >= 2 + 5, "{} images", images.len());
    assert_eq!(images.len(), html.matches("<img ").count());
    for (k, i) in images.iter().enumerate() {
        assert!(
            i[0] == true && i[1].as_u64() > Some(0) && i[2].as_u64() > Some(0),
            "image {k} did not load: {i}"
        );
        assert_eq!(decoded[k], true, "image {k} does not decode: {i}");
    }
    // The plots: inline SVG, a marker with a tooltip per configuration in each.
    let rows = b.eval("document.querySelector('table.sortable').tBodies[0].rows.length");
    let rows = rows.as_u64().expect("row count") as usize;
    let plots = b.eval(
        "[...document.querySelectorAll('.plot svg')].map(s => \
         [s.querySelectorAll('g.pt').length, s.querySelectorAll('g.pt > title').length, \
          s.getBoundingClientRect().width])",
    );
    let plots = plots.as_array().expect("plots");
    assert_eq!(plots.len(), 3, "{plots:?}");
    for p in plots {
        assert!(
            p[0].as_u64() == Some(rows as u64)
                && p[1].as_u64() == Some(rows as u64)
                && p[2].as_f64() > Some(100.0),
            "{p} for {rows} rows"
        );
    }
    // The crossover against PCSS: its plot drawn (two lines per compared configuration, each
    // with a tooltip, laid out wider than 100 px) and a table row per technique compared, as
    // report.json has them.
    let json: Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("report.json")).expect("report.json"),
    )
    .expect("report.json parses");
    let cross = &json["crossover"];
    let costs = cross["costs"].as_array().map_or(0, Vec::len);
    let pairs = cross["pairs"].as_array().map_or(0, Vec::len);
    assert!(costs >= 2 && pairs >= 1, "no crossover: {cross}");
    let drawn = b.eval(
        "(() => { const s = document.querySelector('.crossover-plot svg');\
         return s ? [s.querySelectorAll('path.xo-line').length,\
           s.querySelectorAll('path.xo-line > title').length, s.getBoundingClientRect().width,\
           document.querySelectorAll('table.crossover tbody tr').length] : null; })()",
    );
    assert_eq!(drawn[0].as_u64(), Some(2 * costs as u64), "{drawn}");
    assert_eq!(drawn[1].as_u64(), Some(2 * costs as u64), "{drawn}");
    assert!(drawn[2].as_f64() > Some(100.0), "{drawn}");
    assert_eq!(drawn[3].as_u64(), Some(pairs as u64), "{drawn}");
    // The verdict: at the top, each configuration it names (in bold) a row of the table, and
    // its cheapest configuration within 10% of the best penumbra error the table's.
    let verdict = b.eval(
        "(() => { const lines = [...document.querySelectorAll('li.verdict-line')];\
         const plot = document.querySelector('.plot');\
         const before = lines.length > 0 && (lines[lines.length - 1]\
           .compareDocumentPosition(plot) & Node.DOCUMENT_POSITION_FOLLOWING) !== 0;\
         return [before, lines.map(l => [l.textContent, [...l.querySelectorAll('b')]\
           .map(b => b.textContent)])]; })()",
    );
    assert_eq!(
        verdict[0], true,
        "the verdict is not above the plots: {verdict}"
    );
    let lines = verdict[1].as_array().expect("verdict lines");
    assert!(lines.len() >= 4, "{lines:?}");
    let table = b.eval(
        "(() => { const t = document.querySelector('table.sortable');\
         const h = [...t.tHead.rows[0].cells].map(c => c.textContent);\
         const tc = h.indexOf('total'), pc = h.indexOf('penumbra mean');\
         return [...t.tBodies[0].rows].map(r => [r.cells[0].textContent,\
           parseFloat(r.cells[tc].dataset.v), parseFloat(r.cells[pc].dataset.v)]); })()",
    );
    let table: Vec<(String, f64, f64)> = table
        .as_array()
        .expect("table")
        .iter()
        .map(|r| {
            let num = |v: &Value| v.as_f64().expect("a number");
            (
                r[0].as_str().expect("label").to_string(),
                num(&r[1]),
                num(&r[2]),
            )
        })
        .collect();
    for l in lines {
        for named in l[1].as_array().expect("bold names") {
            let named = named.as_str().expect("a name");
            assert!(table.iter().any(|r| r.0 == named), "{named} is not a row");
        }
    }
    let best = table.iter().map(|r| r.2).fold(f64::INFINITY, f64::min);
    let cheapest = table
        .iter()
        .filter(|r| r.2 <= 1.1 * best)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("a row");
    let line = lines
        .iter()
        .find(|l| l[0].as_str().is_some_and(|t| t.starts_with("Cheapest")))
        .expect("the cheapest line");
    assert_eq!(line[1][0].as_str(), Some(cheapest.0.as_str()), "{line}");
    // Every crop caption gives its configuration's time.
    let captions =
        b.eval("[...document.querySelectorAll('figcaption.crop-caption')].map(c => c.textContent)");
    let captions = captions.as_array().expect("captions");
    assert!(!captions.is_empty());
    for c in captions {
        assert!(c.as_str().is_some_and(|t| t.contains(" ms")), "{c}");
    }
    // The table sorts: ascending, then descending, by total time.
    let sorted = |b: &mut Browser| -> Vec<f64> {
        let v = b.eval(
            "(() => { const t = document.querySelector('table.sortable');\
             const col = [...t.tHead.rows[0].cells].findIndex(c => c.textContent.startsWith('total'));\
             t.tHead.rows[0].cells[col].click();\
             return [...t.tBodies[0].rows].map(r => parseFloat(r.cells[col].dataset.v)); })()",
        );
        v.as_array()
            .expect("column values")
            .iter()
            .map(|x| x.as_f64().expect("a number"))
            .collect()
    };
    let up = sorted(&mut b);
    assert!(
        up.len() >= 5 && up.windows(2).all(|w| w[0] <= w[1]),
        "{up:?}"
    );
    let down = sorted(&mut b);
    assert!(down.windows(2).all(|w| w[0] >= w[1]), "{down:?}");
    // A screenshot of the first screen is not blank: many colours, and a fair share of
    // pixels that are not the background.
    let shot = b.page("Page.captureScreenshot", json!({"format": "png"}));
    let png = base64::engine::general_purpose::STANDARD
        .decode(shot["data"].as_str().expect("screenshot data"))
        .expect("base64");
    let img = image::load_from_memory(&png).expect("PNG").to_rgb8();
    assert_eq!(img.dimensions(), (1280, 1000));
    let mut colours = std::collections::HashMap::new();
    for p in img.pixels() {
        *colours.entry(p.0).or_insert(0usize) += 1;
    }
    let background = colours.values().copied().max().unwrap_or(0);
    let inked = 1.0 - background as f64 / (1280.0 * 1000.0);
    assert!(
        colours.len() >= 32 && inked > 0.03,
        "{} colours, {inked:.3} inked",
        colours.len()
    );
    let found = problems(&b.events, &page);
    assert!(found.is_empty(), "report.html: {found:#?}");
    eprintln!(
        "{} images, {} colours, {:.1}% inked, {} events",
        images.len(),
        colours.len(),
        100.0 * inked,
        b.events.len()
    );
}
