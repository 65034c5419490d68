// The page of `logicrag serve`: picks a window, shows its frames with boxes
// and track ids, a bird's-eye view of its tracks, its facts with
// provenance, and asks questions through the JSON API. Every text from the
// server is set as text (never as HTML), so a fact or an object name
// cannot inject markup. `/?window=ID&q=QUESTION` opens a window and asks on
// load; the address is kept in step, so it can be shared.
"use strict";

const params = new URLSearchParams(location.search);
// Behind a token, the page is opened as /?access_token=T and sends the
// token with every request it makes (RFC 6750 bearer token).
const token = params.get("access_token");
const SVG = "http://www.w3.org/2000/svg";
// Same colours as the plots (logicrag::plot::class_color).
const CLASS_COLORS = { Vehicles: "#1f77b4", Pedestrian: "#d62728", Person: "#d62728", Cyclist: "#9467bd", Misc: "#8c564b" };
const colorOf = (cls) => CLASS_COLORS[cls] || "#7f7f7f";
// Road users move and are what questions are mostly about; the scenery
// (poles, buildings, surfaces) is drawn only on request or when an answer
// names it, so that it does not bury them.
const ROAD_USERS = new Set(["Vehicles", "Pedestrian", "Person", "Cyclist", "Misc"]);

const state = { info: null, window: null, scene: null, frame: 0, bound: new Set() };

const $ = (id) => document.getElementById(id);

function el(tag, attrs, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (k === "class") e.className = v; else e.setAttribute(k, v);
  }
  for (const c of children) e.append(c instanceof Node ? c : document.createTextNode(String(c)));
  return e;
}

function svg(tag, attrs, text) {
  const e = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  if (text !== undefined) e.textContent = text;
  return e;
}

function withToken(url) {
  if (!token) return url;
  return url + (url.includes("?") ? "&" : "?") + "access_token=" + encodeURIComponent(token);
}

async function api(path, body) {
  const opts = { headers: {} };
  if (token) opts.headers["Authorization"] = "Bearer " + token;
  if (body !== undefined) {
    opts.method = "POST";
    opts.headers["Content-Type"] = "application/json";
    opts.body = JSON.stringify(body);
  }
  const resp = await fetch(path, opts);
  const data = await resp.json().catch(() => ({}));
  if (!resp.ok) throw new Error((data.error && data.error.message) || resp.statusText);
  return data;
}

function status(text, isError) {
  const s = $("status");
  s.textContent = text;
  s.className = isError ? "error" : "muted";
}

// ---- windows ------------------------------------------------------------

async function loadWindow(id) {
  state.window = state.info.windows.find((w) => w.id === id) || state.info.windows[0];
  $("window").value = state.window.id;
  state.frame = 0;
  state.scene = null;
  const facts = api("/api/facts?window=" + encodeURIComponent(state.window.id));
  if (state.info.scene) {
    state.scene = await api("/api/scene?window=" + encodeURIComponent(state.window.id));
  }
  renderFrames();
  renderBev();
  renderFacts((await facts).facts);
}

function frameCount() {
  return state.window.last_frame - state.window.first_frame + 1;
}

function frameUrl(index) {
  return withToken("/api/frame?window=" + encodeURIComponent(state.window.id) + "&index=" + index);
}

function renderFrames() {
  const n = frameCount();
  const slider = $("frame-slider");
  slider.max = String(n - 1);
  slider.value = String(state.frame);
  const strip = $("frame-strip");
  strip.replaceChildren();
  if (state.info.images) {
    for (let i = 0; i < n; i++) {
      const t = el("img", { src: frameUrl(i), alt: "frame " + (state.window.first_frame + i), loading: "lazy" });
      t.addEventListener("click", () => { state.frame = i; slider.value = String(i); showFrame(); });
      strip.append(t);
    }
  }
  showFrame();
}

function showFrame() {
  const i = state.frame;
  const frameNo = state.window.first_frame + i;
  $("frame-label").textContent = "frame " + frameNo + " (" + (i + 1) + " of " + frameCount() + ")";
  [...$("frame-strip").children].forEach((t, k) => t.classList.toggle("on", k === i));
  const view = $("frame-view");
  view.replaceChildren();
  const scene = state.scene;
  const w = scene ? scene.image_width : 1242, h = scene ? scene.image_height : 375;
  if (state.info.images) {
    const img = el("img", { id: "frame-img", src: frameUrl(i), alt: "frame " + frameNo });
    // Marks a picture the browser has decoded (the browser test reads it).
    img.addEventListener("load", () => { img.dataset.loaded = "true"; });
    view.append(img);
  } else {
    view.style.aspectRatio = w + " / " + h;
    view.append(el("div", { class: "noimg" }, scene ? "this source has no pictures: boxes only" : "this source has no pictures or boxes (facts only)"));
  }
  if (!scene) return;
  const overlay = svg("svg", { viewBox: "0 0 " + w + " " + h, preserveAspectRatio: "none", id: "frame-boxes" });
  const boxes = (scene.frames[i] || { boxes: [] }).boxes;
  const unit = w / 640;
  const scenery = $("scenery").checked;
  for (const b of boxes) {
    const [l, t, r, btm] = b.bbox;
    const c = colorOf(b.class);
    const hit = state.bound.has(b.name);
    if (!ROAD_USERS.has(b.class) && !hit) {
      if (scenery) overlay.append(svg("rect", { x: l, y: t, width: r - l, height: btm - t, fill: "none", stroke: "#e5e7eb", "stroke-width": unit, "stroke-dasharray": 4 * unit + " " + 3 * unit }));
      continue;
    }
    overlay.append(svg("rect", { x: l, y: t, width: r - l, height: btm - t, fill: "none", stroke: hit ? "#f2a93b" : c, "stroke-width": (hit ? 3 : 1.6) * unit }));
    const label = b.name + " #" + b.track_id;
    const fs = 11 * unit;
    const ty = Math.max(t - 3 * unit, fs);
    overlay.append(svg("rect", { x: l, y: ty - fs, width: label.length * fs * 0.6 + 4 * unit, height: fs + 3 * unit, fill: hit ? "#f2a93b" : c, opacity: 0.85 }));
    overlay.append(svg("text", { x: l + 2 * unit, y: ty, "font-size": fs, fill: "#fff", "font-family": "sans-serif" }, label));
  }
  view.append(overlay);
}

// ---- bird's-eye view ----------------------------------------------------

function renderBev() {
  const view = $("bev-view");
  view.replaceChildren();
  const scene = state.scene;
  if (!scene || (scene.tracks.length === 0 && scene.ego.length < 2)) {
    view.append(el("p", { class: "muted" }, "No tracks with positions in this window."));
    return;
  }
  const W = 520, H = 460, pad = 34;
  const pts = scene.tracks.flatMap((t) => t.points).concat(scene.ego);
  let x0 = Math.min(0, ...pts.map((p) => p.x)) - 3, x1 = Math.max(0, ...pts.map((p) => p.x)) + 3;
  let z0 = Math.min(0, ...pts.map((p) => p.z)) - 3, z1 = Math.max(0, ...pts.map((p) => p.z)) + 3;
  // Equal metres across and ahead: widen the narrower range.
  const s = Math.min((W - 2 * pad) / (x1 - x0), (H - 2 * pad) / (z1 - z0));
  const cx = (x0 + x1) / 2, cz = (z0 + z1) / 2;
  const X = (x) => W / 2 + (x - cx) * s;
  const Y = (z) => H / 2 - (z - cz) * s;
  const root = svg("svg", { viewBox: "0 0 " + W + " " + H, id: "bev" });
  const step = [1, 2, 5, 10, 20, 50, 100].find((m) => m * s >= 40) || 100;
  const gx0 = cx - (W / 2) / s, gx1 = cx + (W / 2) / s, gz0 = cz - (H / 2) / s, gz1 = cz + (H / 2) / s;
  for (let g = Math.ceil(gx0 / step) * step; g <= gx1; g += step) {
    root.append(svg("line", { x1: X(g), y1: 0, x2: X(g), y2: H, stroke: g === 0 ? "#c9ced6" : "#eceef1" }));
    root.append(svg("text", { x: X(g) + 2, y: H - 4, "font-size": 10, fill: "#8a919c" }, g + " m"));
  }
  for (let g = Math.ceil(gz0 / step) * step; g <= gz1; g += step) {
    root.append(svg("line", { x1: 0, y1: Y(g), x2: W, y2: Y(g), stroke: g === 0 ? "#c9ced6" : "#eceef1" }));
    root.append(svg("text", { x: 3, y: Y(g) - 2, "font-size": 10, fill: "#8a919c" }, g + " m"));
  }
  const line = (points, attrs) => svg("polyline", Object.assign({ points: points.map((p) => X(p.x) + "," + Y(p.z)).join(" "), fill: "none" }, attrs));
  root.append(line(scene.ego, { stroke: "#111", "stroke-width": 3, "stroke-dasharray": "6 3" }));
  for (const t of scene.tracks) {
    const c = colorOf(t.class);
    const hit = state.bound.has(t.name);
    const g = svg("g", { "data-track": t.name });
    if (!ROAD_USERS.has(t.class) && !hit) {
      // Scenery stands still: a small square where it is.
      const p = t.points[t.points.length - 1];
      g.append(svg("rect", { x: X(p.x) - 3, y: Y(p.z) - 3, width: 6, height: 6, fill: "#b7bcc4" }));
      g.append(svg("text", { x: X(p.x) + 5, y: Y(p.z) + 3, "font-size": 9, fill: "#9aa1ab" }, t.name));
      g.append(svg("title", {}, t.name + " (" + t.class + ")"));
      root.append(g);
      continue;
    }
    if (hit) g.append(line(t.points, { stroke: "#f2a93b", "stroke-width": 8, opacity: 0.6 }));
    g.append(line(t.points, { stroke: c, "stroke-width": 2.2 }));
    const a = t.points[0], b = t.points[t.points.length - 1];
    g.append(svg("circle", { cx: X(a.x), cy: Y(a.z), r: 3.5, fill: "#fff", stroke: c, "stroke-width": 1.5 }));
    g.append(svg("circle", { cx: X(b.x), cy: Y(b.z), r: 4.5, fill: c }));
    g.append(svg("text", { x: X(b.x) + 6, y: Y(b.z) - 6, "font-size": 11, fill: "#1d2330", "font-weight": hit ? 700 : 400 }, t.name + " #" + t.track_id));
    g.append(svg("title", {}, t.name + " (" + t.class + (t.color ? ", " + t.color : "") + "), frames " + a.frame + "–" + b.frame));
    root.append(g);
  }
  root.append(svg("polygon", { points: [[0, -10], [-7, 6], [7, 6]].map(([dx, dy]) => (X(0) + dx) + "," + (Y(0) + dy)).join(" "), fill: "#111" }));
  root.append(svg("text", { x: X(0) + 9, y: Y(0) + 4, "font-size": 11, "font-weight": 700 }, "ego"));
  view.append(root);
}

// ---- facts --------------------------------------------------------------

function renderFacts(facts) {
  state.facts = facts;
  filterFacts();
}

function factText(f) {
  return f.predicate + "(" + f.args.join(", ") + ")";
}

function isHit(f) {
  return f.args.some((a) => state.bound.has(a));
}

function filterFacts() {
  const q = $("facts-filter").value.trim().toLowerCase();
  const body = $("facts").tBodies[0];
  body.replaceChildren();
  let shown = 0;
  // Facts about the objects of the answer first, in their order.
  const facts = (state.facts || []).slice().sort((a, b) => isHit(b) - isHit(a));
  for (const f of facts) {
    const text = factText(f);
    if (q && !text.toLowerCase().includes(q)) continue;
    const hit = isHit(f);
    body.append(el("tr", { class: hit ? "hit" : "" }, el("td", {}, el("code", {}, text)), el("td", {}, f.why || "")));
    shown++;
  }
  const all = (state.facts || []).length;
  $("facts-count").textContent = shown === all ? all + " facts" : shown + " of " + all + " facts";
}

// ---- answers ------------------------------------------------------------

function proofTree(nodes) {
  const ul = el("ul", { class: "proof" });
  for (const n of nodes) {
    const li = el("li", {}, el("code", {}, n.fact));
    const s = n.step || {};
    let how = "";
    if (s.kind === "observed") {
      const p = s.provenance;
      how = p ? "fact: " + p.source + " window " + p.window + ", frames " + p.frames[0] + "–" + p.frames[1] + (p.note ? ": " + p.note : "") : "fact";
    } else if (s.kind === "rule") how = "rule, line " + s.line + ": " + s.text;
    else if (s.kind === "absent") how = "no such fact (closed world)";
    else if (s.kind === "cut") how = "proof cut: " + s.reason;
    li.append(el("span", { class: "how" + (s.kind === "rule" ? " rule" : "") }, how));
    if (n.premises && n.premises.length) li.append(proofTree(n.premises));
    ul.append(li);
  }
  return ul;
}

function windowResult(r) {
  const box = el("div", { class: "window-result", "data-window": r.window });
  box.append(el("h3", {}, el("span", { class: "badge " + r.answer }, r.answer), "window " + r.window + " · frames " + r.first_frame + "–" + r.last_frame + (r.variables.length ? " · " + r.count + " answer" + (r.count === 1 ? "" : "s") : "")));
  for (const n of r.notes) box.append(el("p", { class: "muted" }, n));
  if (r.answer === "yes") {
    const left = el("div", {});
    if (r.variables.length) {
      const t = el("table", { class: "bindings" }, el("thead", {}, el("tr", {}, ...r.variables.map((v) => el("th", {}, v)))));
      const tb = el("tbody", {});
      for (const b of r.bindings) tb.append(el("tr", {}, ...b.map(([, c]) => el("td", {}, el("code", {}, c)))));
      t.append(tb);
      left.append(el("h4", {}, "Bindings"), t);
    } else {
      left.append(el("p", {}, "The query holds (no variables to bind)."));
    }
    const right = el("div", {}, el("h4", {}, "Proof"));
    r.proofs.forEach((p, i) => {
      const b = r.bindings[i] || [];
      if (b.length) right.append(el("p", { class: "muted" }, b.map(([v, c]) => v + " = " + c).join(", ")));
      right.append(proofTree(p));
    });
    box.append(el("div", { class: "cols" }, left, right));
  } else if (r.answer === "no") {
    const ul = el("ul", { class: "whynot" });
    for (const w of r.why_not) {
      // Each failed entry is a set of literals that cannot hold together.
      ul.append(el("li", {}, w.candidate === "(none)"
        ? w.variable + ": no object of the window satisfies " + w.failed.join(", nor ")
        : w.variable + " = " + w.candidate + ": "
          + (w.satisfied.length ? "holds " + w.satisfied.join(", ") + "; " : "")
          + "cannot hold: " + w.failed.join("; ")));
    }
    box.append(el("h4", {}, "Why not"), r.why_not.length ? ul : el("p", { class: "muted" }, "No candidate comes close."));
  } else {
    const ul = el("ul", { class: "notes" });
    for (const s of r.reasons) ul.append(el("li", {}, s));
    box.append(ul);
  }
  return box;
}

function renderAnswer(data) {
  const out = $("answer");
  out.replaceChildren();
  const s = data.summary;
  out.append(el("div", { class: "headline", id: "answer-headline" }, el("span", { class: "badge " + s.summary.answer }, s.summary.answer), " ", s.headline));
  const q = el("p", { class: "asked" }, s.question ? "“" + s.question + "” → query " : "query ", el("code", { class: "query" }, s.query));
  out.append(q);
  for (const n of s.notes) out.append(el("p", { class: "muted" }, "note: " + n));
  // The windows that say yes first; the others follow.
  const results = data.results.slice().sort((a, b) => (a.answer !== "yes") - (b.answer !== "yes"));
  for (const r of results) out.append(windowResult(r));
}

function renderContext(data) {
  const out = $("context");
  out.replaceChildren();
  const ctx = data.contexts.find((c) => c.window === state.window.id) || data.contexts[0];
  if (!ctx) return;
  const list = (items) => { const ol = el("ol", {}); for (const i of items) ol.append(el("li", {}, i)); return ol; };
  out.append(el("h3", {}, "C2 — inference result"), list(ctx.c2), el("h3", {}, "C3 — scene facts"), list(ctx.c3));
}

async function ask() {
  const question = $("question").value.trim();
  if (!question) return;
  const all = $("all-windows").checked;
  const body = all ? { question } : { question, window: state.window.id };
  $("ask").disabled = true;
  document.body.dataset.state = "asking";
  status("asking…");
  const url = new URL(location.href);
  url.searchParams.set("window", state.window.id);
  url.searchParams.set("q", question);
  history.replaceState(null, "", url);
  try {
    const [answer, context] = await Promise.all([
      api("/api/ask", body),
      api("/api/context", { question, window: state.window.id }),
    ]);
    // Every constant bound in the shown window's answer: [[["x", "car_1"], …], …].
    state.bound = new Set(answer.results.filter((r) => r.window === state.window.id).flatMap((r) => r.bindings.flat().map(([, c]) => c)));
    renderAnswer(answer);
    renderContext(context);
    showFrame();
    renderBev();
    filterFacts();
    status("answered over " + answer.results.length + " window" + (answer.results.length === 1 ? "" : "s"));
    document.body.dataset.state = "answered";
  } catch (e) {
    $("answer").replaceChildren(el("p", { class: "error", id: "answer-error" }, e.message));
    status(e.message, true);
    document.body.dataset.state = "error";
  } finally {
    $("ask").disabled = false;
  }
}

async function main() {
  try {
    state.info = await api("/api/windows");
  } catch (e) {
    status("cannot load the windows: " + e.message, true);
    document.body.dataset.state = "error";
    return;
  }
  $("source").textContent = state.info.source + " · " + state.info.windows.length + " windows";
  // A facts: source has neither pictures nor tracks: nothing to show there.
  $("frames-card").hidden = !state.info.images && !state.info.scene;
  $("bev-card").hidden = !state.info.scene;
  document.title = "logicrag · " + state.info.source;
  const sel = $("window");
  for (const w of state.info.windows) {
    sel.append(el("option", { value: w.id }, w.id + " (frames " + w.first_frame + "–" + w.last_frame + ", " + w.objects + " objects)"));
  }
  sel.addEventListener("change", async () => {
    state.bound = new Set();
    await loadWindow(sel.value);
    const url = new URL(location.href);
    url.searchParams.set("window", sel.value);
    history.replaceState(null, "", url);
    if ($("question").value.trim()) ask();
  });
  $("frame-slider").addEventListener("input", (e) => { state.frame = Number(e.target.value); showFrame(); });
  $("scenery").addEventListener("change", showFrame);
  $("facts-filter").addEventListener("input", filterFacts);
  $("ask-form").addEventListener("submit", (e) => { e.preventDefault(); ask(); });
  await loadWindow(params.get("window") || state.info.windows[0].id);
  document.body.dataset.state = "ready";
  const q = params.get("q");
  if (q) {
    $("question").value = q;
    await ask();
  } else {
    status("ready");
  }
}

main();
