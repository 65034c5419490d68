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
// The map under the tracks, as the plots draw it (logicrag::plot): lane
// fills by kind (intersections darker), drivable areas, crosswalks.
const MAP_COLORS = {
  drivable: "#e4e6ea", outline: "#b0b6be", crosswalk: "#ffe27a", crosswalkOutline: "#cca020",
  lane: { Vehicle: "#d6dae1", Bus: "#fad6b4", Bike: "#c8e8c4" }, intersection: "#cbd0d8",
};

const state = { info: null, window: null, scene: null, frame: 0, bound: new Set(), whyNot: new Set() };

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

// A message at the top of the page (empty: none).
function notice(text) {
  const n = $("notice");
  n.textContent = text;
  n.hidden = !text;
}

function status(text, isError) {
  const s = $("status");
  s.textContent = text;
  s.className = isError ? "error" : "muted";
}

// ---- windows ------------------------------------------------------------

async function loadWindow(id, frame) {
  state.window = state.info.windows.find((w) => w.id === id) || state.info.windows[0];
  $("window").value = state.window.id;
  state.frame = Math.min(Math.max(0, Math.floor(Number(frame) || 0)), frameCount() - 1);
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

// Whether frame `index` of the shown window has a picture. Servers that do
// not list `image_frames` have pictures of every frame when they have any.
function hasImage(index) {
  if (!state.info.images) return false;
  const frames = state.window.image_frames;
  return !frames || frames.includes(state.window.first_frame + index);
}

// "frames 10–19", or "frame 12", or "frames 11–14, 16–19": the frames of
// the window that have no picture, as runs.
function missingFrames() {
  const runs = [];
  for (let i = 0; i < frameCount(); i++) {
    if (hasImage(i)) continue;
    const f = state.window.first_frame + i;
    const last = runs[runs.length - 1];
    if (last && last[1] === f - 1) last[1] = f; else runs.push([f, f]);
  }
  const n = runs.reduce((k, [a, b]) => k + b - a + 1, 0);
  return (n === 1 ? "frame " : "frames ") + runs.map(([a, b]) => a === b ? String(a) : a + "–" + b).join(", ");
}

// The placeholder shown where a frame has no picture: it keeps the frame's
// shape, so the boxes are still drawn where they belong.
function noImage(frameNo) {
  const some = state.window.image_frames && state.window.image_frames.length
    ? " (pictures of frame" + (state.window.image_frames.length === 1 ? " " : "s ") + state.window.image_frames.join(", ") + ")" : "";
  return el("div", { class: "noimg placeholder", id: "frame-placeholder", "data-frame": frameNo },
    "no camera image for " + missingFrames() + some);
}

// The shown state in the address, so that a link opens the same view.
function syncUrl() {
  const url = new URL(location.href);
  const set = (k, v) => { if (v) url.searchParams.set(k, v); else url.searchParams.delete(k); };
  set("window", state.window && state.window.id);
  set("q", $("question").value.trim());
  set("all", $("all-windows").checked ? "1" : "");
  set("frame", state.frame ? String(state.frame) : "");
  set("scenery", $("scenery").checked ? "1" : "");
  set("filter", $("facts-filter").value.trim());
  history.replaceState(null, "", url);
}

// Greedy label placement: each label takes the first candidate position
// (offsets around its anchor) that overlaps no label placed before it and
// stays inside the picture; failing that its short form is tried; failing
// that it is left out (the box keeps its tooltip). Returns [x, y, text,
// moved] with (x, y) the top-left corner, or null.
function placeLabel(placed, texts, anchor, size, bounds, offsets) {
  for (const text of texts) {
    const [w, h] = size(text);
    for (const [dx, dy, moved] of offsets(w, h)) {
      const x = anchor[0] + dx, y = anchor[1] + dy;
      if (x < bounds[0] || y < bounds[1] || x + w > bounds[2] || y + h > bounds[3]) continue;
      if (placed.some((p) => x < p[0] + p[2] && p[0] < x + w && y < p[1] + p[3] && p[1] < y + h)) continue;
      placed.push([x, y, w, h]);
      return [x, y, text, moved, w, h];
    }
  }
  return null;
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
      const frameNo = state.window.first_frame + i;
      const t = hasImage(i)
        ? el("img", { src: frameUrl(i), alt: "frame " + frameNo, loading: "lazy" })
        : el("span", { class: "thumb-none", title: "no camera image for frame " + frameNo }, String(frameNo));
      t.addEventListener("click", () => { state.frame = i; slider.value = String(i); showFrame(); syncUrl(); });
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
  view.style.aspectRatio = w + " / " + h;
  view.classList.toggle("no-image", !hasImage(i));
  if (hasImage(i)) {
    const img = el("img", { id: "frame-img", src: frameUrl(i), alt: "frame " + frameNo });
    // Marks a picture the browser has decoded (the browser test reads it).
    img.addEventListener("load", () => { img.dataset.loaded = "true"; });
    // A picture that fails to load becomes the placeholder, never a
    // broken-image icon.
    img.addEventListener("error", () => img.replaceWith(el("div", { class: "noimg placeholder", id: "frame-placeholder" }, "no camera image for frame " + frameNo)));
    view.append(img);
  } else if (state.info.images) {
    view.append(noImage(frameNo));
  } else {
    // A 360° log's objects have no pixel boxes: only the bird's-eye view shows them.
    const boxless = scene && scene.frames.every((f) => f.boxes.length === 0) && scene.tracks.length > 0;
    view.append(el("div", { class: "noimg" }, boxless ? "this source has no pictures and its objects no pixel boxes (a 360° log): see the bird's-eye view"
      : scene ? "this source has no pictures: boxes only" : "this source has no pictures or boxes (facts only)"));
  }
  if (!scene) return;
  const overlay = svg("svg", { viewBox: "0 0 " + w + " " + h, preserveAspectRatio: "none", id: "frame-boxes" });
  const boxes = (scene.frames[i] || { boxes: [] }).boxes;
  const unit = w / 640;
  const scenery = $("scenery").checked;
  const labels = [];
  for (const b of boxes) {
    const [l, t, r, btm] = b.bbox;
    const c = colorOf(b.class);
    const hit = state.bound.has(b.name);
    const near = !hit && state.whyNot.has(b.name);
    if (!ROAD_USERS.has(b.class) && !hit && !near) {
      if (scenery) overlay.append(svg("rect", { x: l, y: t, width: r - l, height: btm - t, fill: "none", stroke: "#e5e7eb", "stroke-width": unit, "stroke-dasharray": 4 * unit + " " + 3 * unit }));
      continue;
    }
    const rect = svg("rect", { x: l, y: t, width: r - l, height: btm - t, fill: "none", stroke: hit ? "#f2a93b" : near ? "#6e40c9" : c, "stroke-width": (hit || near ? 3 : 1.6) * unit, class: hit ? "box hit" : near ? "box whynot" : "box" });
    if (near) rect.setAttribute("stroke-dasharray", 6 * unit + " " + 3 * unit);
    rect.append(svg("title", {}, b.name + " #" + b.track_id + " (" + b.class + ")" + (near ? ": a why-not candidate" : "")));
    overlay.append(rect);
    labels.push({ b, c, hit, near });
  }
  // Labels of the answer's objects first, then why-not candidates, then
  // the nearest (lowest in the picture) first: they win the free spots.
  const rank = (x) => (x.hit ? 0 : x.near ? 1 : 2);
  labels.sort((p, q) => rank(p) - rank(q) || q.b.bbox[3] - p.b.bbox[3]);
  const fs = 11 * unit, pad = 2 * unit, lh = fs + 3 * unit;
  const size = (text) => [text.length * fs * 0.6 + 2 * pad, lh];
  const placed = [];
  for (const { b, c, hit, near } of labels) {
    const [l, t, r, btm] = b.bbox;
    // Above the box, inside its top, below it, left, right; then further
    // up and down, moved (with a leader line).
    const offsets = (lw) => [
      [0, -lh - unit, false], [0, 0, false], [0, btm - t + unit, false],
      [-lw - unit, 0, false], [r - l + unit, 0, false], [r - l - lw, -lh - unit, false],
      ...[2, 3, 4, 5].flatMap((k) => [[0, -k * lh - unit, true], [0, btm - t + (k - 1) * lh + unit, true], [-lw - unit, -k * lh, true], [r - l + unit, -k * lh, true]]),
    ];
    const spot = placeLabel(placed, [b.name + " #" + b.track_id, "#" + b.track_id], [l, t], size, [0, 0, w, h], offsets);
    if (!spot) continue;
    const [x, y, text, moved, lw] = spot;
    const fill = hit ? "#f2a93b" : near ? "#6e40c9" : c;
    if (moved) {
      const ax = Math.min(Math.max(x + lw / 2, l), r), ay = y + lh <= t ? t : btm;
      overlay.append(svg("line", { x1: ax, y1: ay, x2: x + lw / 2, y2: y + lh <= t ? y + lh : y, stroke: fill, "stroke-width": unit }));
    }
    overlay.append(svg("rect", { x, y, width: lw, height: lh, fill, opacity: 0.85, class: "label" }));
    overlay.append(svg("text", { x: x + pad, y: y + fs, "font-size": fs, fill: "#fff", "font-family": "sans-serif" }, text));
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
  // Axis labels stay inside the picture: one that would cross the right
  // or top edge goes to the other side of its line, or is left out.
  const placed = [];
  for (let g = Math.ceil(gx0 / step) * step; g <= gx1; g += step) {
    root.append(svg("line", { x1: X(g), y1: 0, x2: X(g), y2: H, stroke: g === 0 ? "#c9ced6" : "#eceef1" }));
    const text = g + " m", tw = text.length * 6;
    const tx = X(g) + 2 + tw <= W ? X(g) + 2 : X(g) - 2 - tw;
    if (tx < 0) continue;
    root.append(svg("text", { x: tx, y: H - 4, "font-size": 10, fill: "#8a919c", class: "axis" }, text));
    placed.push([tx, H - 14, tw, 12]);
  }
  for (let g = Math.ceil(gz0 / step) * step; g <= gz1; g += step) {
    root.append(svg("line", { x1: 0, y1: Y(g), x2: W, y2: Y(g), stroke: g === 0 ? "#c9ced6" : "#eceef1" }));
    const text = g + " m", ty = Y(g) - 2 >= 11 ? Y(g) - 2 : Y(g) + 11;
    if (ty > H - 16) continue;
    root.append(svg("text", { x: 3, y: ty, "font-size": 10, fill: "#8a919c", class: "axis" }, text));
    placed.push([3, ty - 10, text.length * 6, 12]);
  }
  if (scene.map) root.append(mapLayer(scene.map, X, Y));
  // Track labels are placed after every track is drawn, avoiding each
  // other (see placeLabel): answer objects first, then why-not candidates,
  // then road users, then scenery.
  const labels = [];
  const line = (points, attrs) => svg("polyline", Object.assign({ points: points.map((p) => X(p.x) + "," + Y(p.z)).join(" "), fill: "none" }, attrs));
  root.append(line(scene.ego, { stroke: "#111", "stroke-width": 3, "stroke-dasharray": "6 3" }));
  for (const t of scene.tracks) {
    const c = colorOf(t.class);
    const hit = state.bound.has(t.name);
    const near = !hit && state.whyNot.has(t.name);
    const g = svg("g", { "data-track": t.name, class: hit ? "hit" : near ? "whynot" : "" });
    if (!ROAD_USERS.has(t.class) && !hit && !near) {
      // Scenery stands still: a small square where it is.
      const p = t.points[t.points.length - 1];
      g.append(svg("rect", { x: X(p.x) - 3, y: Y(p.z) - 3, width: 6, height: 6, fill: "#b7bcc4" }));
      g.append(svg("title", {}, t.name + " (" + t.class + ")"));
      root.append(g);
      labels.push({ rank: 3, at: [X(p.x), Y(p.z)], texts: [t.name], fs: 9, fill: "#9aa1ab", weight: 400 });
      continue;
    }
    if (hit) g.append(line(t.points, { stroke: "#f2a93b", "stroke-width": 8, opacity: 0.6 }));
    if (near) g.append(line(t.points, { stroke: "#6e40c9", "stroke-width": 8, opacity: 0.45, "stroke-dasharray": "8 4" }));
    g.append(line(t.points, { stroke: c, "stroke-width": 2.2 }));
    const a = t.points[0], b = t.points[t.points.length - 1];
    g.append(svg("circle", { cx: X(a.x), cy: Y(a.z), r: 3.5, fill: "#fff", stroke: c, "stroke-width": 1.5 }));
    g.append(svg("circle", { cx: X(b.x), cy: Y(b.z), r: 4.5, fill: c }));
    if (near) g.append(svg("circle", { cx: X(b.x), cy: Y(b.z), r: 8, fill: "none", stroke: "#6e40c9", "stroke-width": 2, "stroke-dasharray": "3 2" }));
    g.append(svg("title", {}, t.name + " (" + t.class + (t.color ? ", " + t.color : "") + "), frames " + a.frame + "–" + b.frame + (near ? ": a why-not candidate" : "")));
    root.append(g);
    labels.push({ rank: hit ? 0 : near ? 1 : 2, at: [X(b.x), Y(b.z)], texts: [t.name + " #" + t.track_id, "#" + t.track_id], fs: 11, fill: near ? "#6e40c9" : "#1d2330", weight: hit || near ? 700 : 400 });
  }
  root.append(svg("polygon", { points: [[0, -10], [-7, 6], [7, 6]].map(([dx, dy]) => (X(0) + dx) + "," + (Y(0) + dy)).join(" "), fill: "#111" }));
  root.append(svg("text", { x: X(0) + 9, y: Y(0) + 4, "font-size": 11, "font-weight": 700 }, "ego"));
  placed.push([X(0) - 7, Y(0) - 10, 36, 16]);
  labels.sort((p, q) => p.rank - q.rank);
  for (const lb of labels) {
    const lh = lb.fs + 2;
    const size = (text) => [text.length * lb.fs * 0.58, lh];
    // Right-up, right-down, left-up, left-down of the track's end; then
    // further away in those directions, with a leader line.
    const offsets = (w) => [
      [6, -lh - 2, false], [6, 2, false], [-6 - w, -lh - 2, false], [-6 - w, 2, false], [-w / 2, -lh - 6, false], [-w / 2, 6, false],
      ...[1, 2, 3].flatMap((k) => [[6 + 4 * k, -lh - 2 - k * lh, true], [6 + 4 * k, 2 + k * lh, true], [-6 - 4 * k - w, -lh - 2 - k * lh, true], [-6 - 4 * k - w, 2 + k * lh, true]]),
    ];
    const spot = placeLabel(placed, lb.texts, lb.at, size, [0, 0, W, H], offsets);
    if (!spot) continue;
    const [x, y, text, moved, w] = spot;
    if (moved) root.append(svg("line", { x1: lb.at[0], y1: lb.at[1], x2: x < lb.at[0] ? x + w : x, y2: y + lh / 2, stroke: "#9aa1ab", "stroke-width": 0.8 }));
    root.append(svg("text", { x, y: y + lb.fs, "font-size": lb.fs, fill: lb.fill, "font-weight": lb.weight, class: "label" }, text));
  }
  view.append(root);
}

// The map of a 360° log (SceneView.map: polygons of [x, z] points in the
// ego frame): drivable areas, then lanes (named as in the facts,
// `lane_<id>`, an answer's lanes outlined), then crosswalks.
function mapLayer(map, X, Y) {
  const g = svg("g", { class: "map" });
  const poly = (points, attrs, title) => {
    const p = svg("polygon", Object.assign({ points: points.map(([x, z]) => X(x) + "," + Y(z)).join(" ") }, attrs));
    p.append(svg("title", {}, title));
    g.append(p);
  };
  for (const a of map.drivable_areas) poly(a.polygon, { fill: MAP_COLORS.drivable }, "drivable area " + a.id);
  for (const l of map.lanes) {
    const name = "lane_" + l.id;
    const hit = state.bound.has(name);
    const fill = l.is_intersection && l.kind === "Vehicle" ? MAP_COLORS.intersection : MAP_COLORS.lane[l.kind] || MAP_COLORS.lane.Vehicle;
    poly(l.polygon, { fill, stroke: hit ? "#f2a93b" : MAP_COLORS.outline, "stroke-width": hit ? 3 : 0.6 },
      name + " (" + l.kind + (l.is_intersection ? ", in an intersection" : "") + ")");
  }
  for (const c of map.crosswalks) poly(c.polygon, { fill: MAP_COLORS.crosswalk, stroke: MAP_COLORS.crosswalkOutline, "stroke-width": 0.8 }, "crosswalk " + c.id);
  return g;
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

function isNear(f) {
  return f.args.some((a) => state.whyNot.has(a));
}

function filterFacts() {
  const q = $("facts-filter").value.trim().toLowerCase();
  const body = $("facts").tBodies[0];
  body.replaceChildren();
  let shown = 0;
  // Facts about the objects of the answer first, in their order.
  // Then those about why-not candidates.
  const rank = (f) => (isHit(f) ? 0 : isNear(f) ? 1 : 2);
  const facts = (state.facts || []).slice().sort((a, b) => rank(a) - rank(b));
  for (const f of facts) {
    const text = factText(f);
    if (q && !text.toLowerCase().includes(q)) continue;
    const r = rank(f);
    body.append(el("tr", { class: r === 0 ? "hit" : r === 1 ? "whynot" : "" }, el("td", {}, el("code", {}, text)), el("td", {}, f.why || "")));
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
  box.append(el("h3", {}, el("span", { class: "badge " + r.answer }, r.answer), "window " + r.window + " · frames " + r.first_frame + "–" + r.last_frame + (r.variables.length ? " · " + r.count + " answer" + (r.count === 1 ? "" : "s") : "") + (r.probability != null && r.probability < 1 ? " · probability " + r.probability : "")));
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
  syncUrl();
  try {
    const [answer, context] = await Promise.all([
      api("/api/ask", body),
      api("/api/context", { question, window: state.window.id }),
    ]);
    // Every constant bound in the shown window's answer: [[["x", "car_1"], …], …].
    const shown = answer.results.filter((r) => r.window === state.window.id);
    state.bound = new Set(shown.flatMap((r) => r.bindings.flat().map(([, c]) => c)));
    // The objects that came close to a "no": highlighted as candidates.
    state.whyNot = new Set(shown.flatMap((r) => (r.why_not || []).map((w) => w.candidate)).filter((c) => c !== "(none)" && !state.bound.has(c)));
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
  // What the source skipped is said, with its reasons on hover.
  const skipped = state.info.skipped || [];
  if (skipped.length) {
    const n = skipped.reduce((k, s) => k + s.count, 0);
    $("source").textContent += " · " + n + " inputs skipped";
    $("source").title = skipped.map((s) => s.count + ": " + s.reason + (s.example ? " (e.g. " + s.example + ")" : "")).join("\n");
  }
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
    state.whyNot = new Set();
    notice("");
    await loadWindow(sel.value);
    syncUrl();
    if ($("question").value.trim()) ask();
  });
  $("frame-slider").addEventListener("input", (e) => { state.frame = Number(e.target.value); showFrame(); syncUrl(); });
  $("scenery").addEventListener("change", () => { showFrame(); syncUrl(); });
  $("facts-filter").addEventListener("input", () => { filterFacts(); syncUrl(); });
  $("all-windows").addEventListener("change", syncUrl);
  $("ask-form").addEventListener("submit", (e) => { e.preventDefault(); ask(); });
  // Every choice of the link: window, question, all windows, frame,
  // scenery boxes, facts filter.
  $("all-windows").checked = params.get("all") === "1";
  $("scenery").checked = params.get("scenery") === "1";
  $("facts-filter").value = params.get("filter") || "";
  const wanted = params.get("window");
  const known = !wanted || state.info.windows.some((w) => w.id === wanted);
  await loadWindow(known && wanted ? wanted : state.info.windows[0].id, params.get("frame"));
  document.body.dataset.state = "ready";
  const q = params.get("q");
  if (!known) {
    // Never silently another window: say so, and do not answer the
    // link's question about a window that is not there.
    const msg = "this server has no window “" + wanted + "” (the link's): showing " + state.window.id + " instead" + (q ? "; press Ask to ask the link's question here" : "");
    notice(msg);
    status(msg, true);
    if (q) $("question").value = q;
    document.body.dataset.state = "unknown-window";
    return;
  }
  if (q) {
    $("question").value = q;
    await ask();
  } else {
    status("ready");
  }
}

main();
