// physcam serve: the page. The numbers come from the server's /api/report (the CLI's --json); with a
// thin lens or a datasheet the page's own solver (onset.js, the same report in JavaScript) answers
// first and whenever the server cannot be reached, so the page works with the laptop off (sw.js keeps
// the page and the camera table). This script reads the form, keeps the setup in the URL, formats lengths.
"use strict";

const $ = (id) => document.getElementById(id);
const DEBOUNCE_MS = 25; // the numbers: as soon as typing pauses for a moment
const SETTLE_MS = 250; // the table, the chart and the diagram: once the setup has settled
const DEFAULT_SENSOR = "s35-4perf";
const DEFAULT_COC = "d/1500";
const COCS = ["d/1500", "d/1000", "d/1730", "cine", "full-frame", "16mm"];
const MARKS = {
  metric: ["0.5m", "0.75m", "1m", "1.25m", "1.5m", "2m", "2.5m", "3m", "4m", "5m", "7m", "10m", "15m", "20m"],
  imperial: ["2ft", "3ft", "4ft", "5ft", "6ft", "7ft", "8ft", "10ft", "12ft", "15ft", "20ft", "25ft", "35ft", "50ft"],
};
const DEFAULTS = { focal: "50", fstop: "2.8", focus: "3m" };

const st = { units: "metric", lensmode: "focal", solve: "dof", report: null, squeezeFromFormat: false, sensorAsked: null };
let SENSORS = [];
let timer = null;
let settle = null;
let seq = 0;
const controllers = {};

// --- lengths as said on set ---------------------------------------------------------------
function roundHalfEven(x) {
  const r = Math.round(x);
  return Math.abs(x % 1) === 0.5 && r % 2 !== 0 ? r - 1 : r;
}

function feetInches(mm) {
  // as physcam.units.format_feet_inches: feet and inches to the nearest inch
  const total = roundHalfEven(mm / 25.4);
  const sign = total < 0 ? "-" : "";
  const a = Math.abs(total);
  return `${sign}${Math.floor(a / 12)}' ${a % 12}"`;
}

function fmtLen(mm) {
  if (mm === null || mm === undefined) return "∞";
  if (st.units === "imperial") {
    return Math.abs(mm) < 304.8 ? `${(mm / 25.4).toFixed(1)}"` : feetInches(mm);
  }
  return Math.abs(mm) < 1000 ? `${(mm / 10).toFixed(1)} cm` : `${(mm / 1000).toFixed(2)} m`;
}

function showLen(el, mm) {
  el.dataset.mm = mm === null || mm === undefined ? "inf" : String(mm);
  el.textContent = fmtLen(mm);
}

const BARE = /^\s*[+-]?(\d+(\.\d*)?|\.\d+)\s*$/;

// physcam's one rule (docs/serve.md): a bare focus, near or far is millimetres in metric and feet in
// imperial, here as on the command line; the server reads it (the request says its units)
function withUnit(text) {
  const t = text.trim();
  return /^(inf|infinity|∞)$/i.test(t) ? "inf" : t;
}

function bareAsWritten(text) {
  // what a bare number meant before the units switch, written out
  return BARE.test(text) ? text.trim() + (st.units === "imperial" ? "ft" : "mm") : text;
}

function stop(text) {
  // "f/2.8", "F2.8", "T2.9" and "2.8" all mean the number
  const m = /^\s*[fFtT]\s*\/?\s*(.+)$/.exec(text);
  return (m ? m[1] : text).trim();
}

const val = (id) => $(id).value.trim();

// --- the request ---------------------------------------------------------------------------
function apiParams() {
  const p = new URLSearchParams();
  if (st.lensmode === "library") {
    if (val("lens")) p.set("lens", val("lens"));
  } else if (val("focal")) {
    p.set("focal", val("focal"));
  }
  const s = $("sensor").value;
  if (s === "custom") {
    if (val("sensor-width")) p.set("sensor-width", val("sensor-width"));
    if (val("sensor-height")) p.set("sensor-height", val("sensor-height"));
  } else if (s) {
    // a bare camera name the page was opened with ("ALEXA 35"), while its format is still chosen: asked by that
    // name, so the report (the page's, the server's) says which format it is, as the CLI's does
    p.set("sensor", st.sensorAsked && st.sensorAsked.key === s ? st.sensorAsked.name : s);
  }
  if ($("squeeze").value !== "1") p.set("squeeze", $("squeeze").value);
  if (st.solve !== "fstop" && val("fstop")) p.set("fstop", stop(val("fstop")));
  if (val("tstop")) p.set("tstop", stop(val("tstop")));
  if (st.solve !== "focus" && val("focus")) p.set("focus", withUnit(val("focus")));
  if (st.solve !== "dof") {
    if (val("near")) p.set("near", withUnit(val("near")));
    if (val("far")) p.set("far", withUnit(val("far")));
  }
  const coc = $("coc").value;
  if (coc === "custom") {
    if (val("coc-mm")) p.set("coc", val("coc-mm"));
  } else if (coc !== DEFAULT_COC) {
    p.set("coc", coc);
  }
  p.set("units", st.units === "imperial" ? "ft" : "m"); // how to read a bare focus, near or far
  return p;
}

function pageParams(api) {
  const p = new URLSearchParams(api);
  if (st.solve !== "dof") p.set("solve", st.solve);
  if (st.units !== "metric") p.set("units", st.units);
  return p;
}

async function getJSON(kind, url) {
  if (controllers[kind]) controllers[kind].abort();
  const c = new AbortController();
  controllers[kind] = c;
  const r = await fetch(url, { signal: c.signal, headers: { accept: "application/json" } });
  let body = null;
  try {
    body = await r.json();
  } catch (e) {
    body = { error: `the server answered HTTP ${r.status}` };
  }
  return { ok: r.ok, status: r.status, body };
}

function showMessage(text) {
  const m = $("message");
  m.textContent = text || "";
  m.hidden = !text;
}

function setStale(stale) {
  $("summary").classList.toggle("stale", stale);
  $("details").classList.toggle("stale", stale);
}

function schedule() {
  clearTimeout(timer);
  timer = setTimeout(update, DEBOUNCE_MS);
}

async function update() {
  clearTimeout(timer);
  const my = ++seq;
  const api = apiParams();
  const query = pageParams(api).toString();
  history.replaceState(null, "", query ? `?${query}` : location.pathname);
  $("share-url").value = location.href;
  $("json-link").href = `/api/report?${api}`;
  const local = localReport(api);
  if (local && local.ok) showReport(local.body, "page");
  let res;
  try {
    res = await getJSON("report", `/api/report?${api}`);
  } catch (e) {
    if (e.name === "AbortError") return;
    if (my !== seq) return;
    offline(local, api, my);
    return;
  }
  if (my !== seq) return;
  document.body.dataset.offline = "";
  if (!res.ok) {
    showMessage(res.body && res.body.error ? res.body.error : `the server answered HTTP ${res.status}`);
    setStale(true);
    return;
  }
  showReport(res.body, "server");
  clearTimeout(settle);
  settle = setTimeout(() => {
    if (my !== seq) return;
    chart(api);
    table(res.body, api, my);
    diagram(res.body);
  }, SETTLE_MS);
}

// --- the page's own solver (onset.js): first, and whenever the server is away ---------------------
function localReport(api) {
  if (!window.PhysOnset || api.has("lens") || !SENSORS.length) return null;
  return PhysOnset.report(Object.fromEntries(api), SENSORS);
}

function showReport(d, source) {
  showMessage("");
  setStale(false);
  st.report = d;
  // the CoC in force, in every answer: its value on this sensor and its convention's name
  $("coc-active").textContent = `circle of confusion ${d.coc_mm.toFixed(4)} mm · ${d.coc_convention}`;
  document.body.dataset.source = source; // "page" (onset.js) or "server" (the CLI's numbers)
  render(d);
  if (window.PhysTools) PhysTools.afterReport(d); // frame, split focus, diopters (tools.js)
}

function offline(local, api, my) {
  document.body.dataset.offline = "1";
  if (!local) {
    showMessage("the physcam server cannot be reached: a library lens needs it (its prescription is traced there); "
      + "a focal length is computed in the page");
    setStale(true);
    return;
  }
  if (!local.ok) {
    showMessage(local.body.error);
    setStale(true);
    return;
  }
  showReport(local.body, "page");
  localTable(local.body, api, my);
  $("dof-chart").hidden = true;
}

function localTable(d, api, my) {
  // the focus marks' rows from onset.js, as /api/focus-table would give them
  const p = Object.fromEntries(api);
  for (const k of ["focus", "near", "far", "fstop", "coc"]) delete p[k];
  const marks = MARKS[st.units];
  const rows = marks.map((m) => {
    const r = PhysOnset.report({ ...p, fstop: String(d.fstop), coc: String(d.coc_mm), focus: m }, SENSORS);
    return r.ok ? { focus: m, report: r.body } : { focus: m, error: r.body.error };
  });
  if (my === seq) fillMarks(d, rows, marks);
}

// --- what comes back -------------------------------------------------------------------------
function deg(x) { return `${x.toFixed(1)}°`; }
function num(x, nd) { return String(Number(x.toFixed(nd))); }

function render(d) {
  const dof = d.dof;
  showLen($("out-near"), dof.near_from_film_mm);
  showLen($("out-far"), dof.far_from_film_mm);
  showLen($("out-total"), dof.total_mm);
  showLen($("out-hyperfocal"), dof.hyperfocal_from_film_mm);
  // split focus with the stop given: the limits shown are that stop's; the stop the asked limits need beside them
  const sf = d.split_focus;
  $("split-card").hidden = !sf;
  $("label-near").textContent = sf ? `near at f/${num(d.fstop, 1)}` : "near";
  $("label-far").textContent = sf ? `far at f/${num(d.fstop, 1)}` : "far";
  if (sf) {
    $("out-split").textContent = `f/${num(sf.fstop_needed, 1)} holds ${fmtLen(sf.near_asked_from_film_mm)} – `
      + `${fmtLen(sf.far_asked_from_film_mm)}` + (sf.holds ? "" : ` (f/${num(sf.fstop_given, 1)} holds less)`);
  }
  const f = d.fov_deg.focus, i = d.fov_deg.infinity;
  $("out-fov").textContent = `${deg(f.horizontal)} / ${deg(f.vertical)} / ${deg(f.diagonal)}`;
  $("out-fov-inf").textContent = `${deg(i.horizontal)} / ${deg(i.vertical)} / ${deg(i.diagonal)}`;
  const m = d.magnification; // signed: negative is the inverted image on the film
  $("out-mag").textContent = m === 0 ? "0 (subject at infinity)"
    : `1 : ${(1 / Math.abs(m)).toFixed(1)}  (${m.toFixed(4)}×, inverted image)`;
  const p = d.entrance_pupil_from_film_mm;
  const inches = st.units === "imperial" && p !== null ? ` (${(p / 25.4).toFixed(2)} in)` : "";
  $("out-pupil").textContent = p === null ? "unknown: the report needs a datasheet pupil"
    : `${p.toFixed(1)} mm${inches} · ${d.entrance_pupil_source}`;
  let fs = `f/${num(d.fstop, 2)}` + ("fstop" in d.solved ? " (solved from near/far)" : "");
  if (d.tstop !== null) {
    const drift = d.solved.tstop_drift_stops;
    fs += ` · T${num(d.tstop, 2)}` + (drift !== undefined ? ` (${drift >= 0 ? "+" : ""}${drift.toFixed(2)} stops)` : "");
  }
  $("out-fstop").textContent = fs;
  const fo = $("out-focus");
  showLen(fo, d.focus_from_film_mm);
  if ("focus_from_film_mm" in d.solved) fo.textContent += " (solved from near/far)";
  $("out-coc").textContent = `${d.coc_mm.toFixed(4)} mm (${d.coc_convention})`;
  const h = d.dof_horizontal;
  $("dt-horizontal").hidden = $("out-horizontal").hidden = !h;
  if (h) $("out-horizontal").textContent = `${fmtLen(h.near_from_film_mm)} / ${fmtLen(h.far_from_film_mm)}`;
  $("notes").replaceChildren(...d.notes.map((n) => {
    const li = document.createElement("li");
    li.textContent = n;
    return li;
  }));
}

function chart(api) {
  const img = $("dof-chart");
  const src = `/api/dof.svg?${api}`; // (the units ride on the api's parameters)
  if (img.getAttribute("src") !== src) {
    img.hidden = false;
    img.setAttribute("src", src);
    st.chart = null;
    delete img.dataset.api;
    $("dof-cursor").hidden = true;
    // the chart's axes and curves ride in the SVG's metadata (physcam serve caches the drawing)
    fetch(src).then((r) => (r.ok ? r.text() : "")).then((text) => {
      if (img.getAttribute("src") !== src) return;
      const doc = new DOMParser().parseFromString(text, "image/svg+xml");
      const desc = doc.getElementsByTagName("dc:description")[0]; // (matplotlib writes the dc: prefix)
      st.chart = desc ? JSON.parse(desc.textContent) : null;
      img.dataset.api = api; // the chart and its numbers now answer this setup (tests wait on it)
    }).catch(() => { st.chart = null; });
  }
}

// the value of a chart curve at distance x (mm): linear in log distance between its rows
function logInterp(rows, x, k) {
  for (let i = 1; i < rows.length; i++) {
    const [x0, x1] = [rows[i - 1][0], rows[i][0]];
    if (x0 <= x && x <= x1) {
      const [a, b] = [rows[i - 1][k], rows[i][k]];
      if (a === null || b === null) return x - x0 < x1 - x ? a : b;
      const t = Math.log(x / x0) / Math.log(x1 / x0);
      return Math.exp(Math.log(a) + t * (Math.log(b) - Math.log(a)));
    }
  }
  return undefined;
}

// the mark under the cursor: a line on the chart and, under it, near / far per stop at that focus mark
function chartCursor(ev) {
  const c = st.chart;
  const img = $("dof-chart");
  if (!c || img.hidden) return;
  const r = img.getBoundingClientRect();
  const fx = (ev.clientX - r.left) / r.width;
  const [ax0, ay0, aw, ah] = c.axes;
  const t = (fx - ax0) / aw;
  const line = $("dof-cursor");
  if (t < 0 || t > 1) {
    line.hidden = true;
    return;
  }
  const [lo, hi] = c.x_mm;
  const x = lo * Math.pow(hi / lo, t);
  line.hidden = false;
  line.style.left = `${fx * 100}%`;
  line.style.top = `${(1 - ay0 - ah) * 100}%`;
  line.style.height = `${ah * 100}%`;
  const parts = c.stops.map((s) => {
    const near = logInterp(s.rows, x, 1);
    if (near === undefined) return null;
    const far = s.hyperfocal_mm !== null && x >= s.hyperfocal_mm ? null : logInterp(s.rows, x, 2);
    return `f/${num(s.fstop, 1)}: ${fmtLen(near)} – ${fmtLen(far)}`;
  }).filter(Boolean);
  const out = $("dof-readout");
  out.dataset.mm = String(Math.round(x));
  out.textContent = `focus ${fmtLen(x)} · ${parts.join(" · ")}`;
}

async function table(d, api, my) {
  const p = new URLSearchParams(api);
  for (const k of ["focus", "near", "far", "fstop", "coc"]) p.delete(k);
  p.set("fstop", String(d.fstop));
  p.set("coc", String(d.coc_mm));
  const marks = MARKS[st.units];
  p.set("marks", marks.join(","));
  let res;
  try {
    res = await getJSON("table", `/api/focus-table?${p}`);
  } catch (e) {
    if (e.name !== "AbortError" && localReport(api)) localTable(d, api, my);
    return;
  }
  if (my !== seq || !res.ok) return;
  fillMarks(d, res.body, marks);
}

function fillMarks(d, answers, marks) {
  const body = $("marks").tBodies[0];
  const rows = answers.map((row, k) => {
    const tr = document.createElement("tr");
    tr.dataset.focus = marks[k];
    const label = document.createElement("td");
    label.textContent = marks[k].replace(/^(.*)ft$/, "$1'").replace(/^(.*)m$/, "$1 m");
    tr.append(label);
    if (row.error) {
      const td = document.createElement("td");
      td.colSpan = 3;
      td.className = "err";
      td.textContent = "n/a";
      td.title = row.error;
      tr.append(td);
      return tr;
    }
    const r = row.report;
    if (Math.abs(r.focus_from_film_mm - d.focus_from_film_mm) <= 0.02 * d.focus_from_film_mm) tr.className = "current";
    for (const mm of [r.dof.near_from_film_mm, r.dof.far_from_film_mm, r.dof.total_mm]) {
      const td = document.createElement("td");
      showLen(td, mm);
      tr.append(td);
    }
    return tr;
  });
  body.replaceChildren(...rows);
}

function diagram(d) {
  const sec = $("diagram-section");
  if (st.lensmode !== "library" || !val("lens")) {
    sec.hidden = true;
    return;
  }
  sec.hidden = false;
  const q = new URLSearchParams({ focus: `${d.focus_from_film_mm}mm`, fstop: String(d.fstop) });
  if (st.units === "imperial") q.set("units", "ft");
  const src = `/api/lens/${encodeURIComponent(val("lens"))}/diagram.svg?${q}`;
  const img = $("diagram");
  if (img.getAttribute("src") !== src) {
    img.hidden = false;
    img.setAttribute("src", src);
  }
}

// --- the form ----------------------------------------------------------------------------------
function norm(s) { return String(s).toLowerCase().replace(/[^a-z0-9]+/g, ""); }

function sensorOption(s) {
  return new Option(`${s.name} — ${num(s.width_mm, 2)} × ${num(s.height_mm, 2)} mm`, s.key);
}

function fillSensors(filter) {
  const sel = $("sensor");
  const cur = sel.value;
  const f = norm(filter || "");
  const cam = $("camera").value; // a camera: its recording formats only
  const rows = SENSORS.filter((s) => (!cam || cameraOf(s) === cam)
    && (!f || [s.key, s.name, ...s.aliases].some((x) => norm(x).includes(f))));
  const opts = rows.map(sensorOption);
  if (!rows.length) {
    const keep = SENSORS.find((s) => s.key === cur);
    if (keep) opts.push(sensorOption(keep));
    const none = new Option(`no sensor matches “${filter}”`, "");
    none.disabled = true;
    opts.push(none);
  }
  opts.push(new Option("custom size…", "custom"));
  sel.replaceChildren(...opts);
  const values = [...sel.options].map((o) => o.value);
  sel.value = values.includes(cur) ? cur : (rows.length ? rows[0].key : cur);
  if (sel.value !== cur) sensorChanged();
}

function cameraOf(s) { return s.camera ? `${s.maker} ${s.camera}` : ""; }

function fillCameras() {
  // the camera table's cameras, by maker; "" the sensors and film gates of sensors.csv
  const sel = $("camera");
  const names = [...new Set(SENSORS.map(cameraOf).filter(Boolean))];
  sel.replaceChildren(new Option("all sensors, gates and formats", ""), ...names.map((n) => new Option(n, n)));
}

function findSensor(text) {
  const k = norm(text);
  const s = SENSORS.find((x) => [x.key, x.name, ...x.aliases].some((y) => norm(y) === k));
  return s ? s.key : null;
}

function sensorChanged() {
  $("custom-sensor").hidden = $("sensor").value !== "custom";
  squeezeFromFormat();
  schedule();
}

// an anamorphic recording format's desqueeze (the camera table's, when it gives one): the squeeze follows
// the format unless the user chose another; a format without one puts back the squeeze it set
function squeezeFromFormat() {
  const s = SENSORS.find((x) => x.key === $("sensor").value);
  const offered = s && s.anamorphic && s.anamorphic.length === 1 ? Number(s.anamorphic[0]) : null;
  const sel = $("squeeze");
  if (offered !== null && (sel.value === "1" || st.squeezeFromFormat)) {
    const o = [...sel.options].find((x) => Number(x.value) === offered);
    if (o) sel.value = o.value; else addOption(sel, String(offered), `${offered}×`);
    st.squeezeFromFormat = true;
  } else if (offered === null && st.squeezeFromFormat) {
    sel.value = "1";
    st.squeezeFromFormat = false;
  }
  $("squeeze-hint").hidden = !st.squeezeFromFormat;
  if (st.squeezeFromFormat) $("squeeze-hint").textContent = `${num(offered, 3)}× desqueeze: the camera table's for ${s.name}`;
}

function press(ids, on) {
  for (const id of ids) $(id).setAttribute("aria-pressed", String(id === on));
}

function setLensMode(mode) {
  st.lensmode = mode;
  press(["lensmode-focal", "lensmode-library"], `lensmode-${mode}`);
  $("field-focal").hidden = mode !== "focal";
  $("field-lens").hidden = mode !== "library";
}

function setSolve(mode) {
  st.solve = mode;
  press(["solve-dof", "solve-fstop", "solve-focus"], `solve-${mode}`);
  $("field-fstop").hidden = mode === "fstop";
  $("field-focus").hidden = mode === "focus";
  $("field-measured").hidden = mode === "dof";
}

function setUnits(units, convert) {
  if (convert && units !== st.units) {
    // a bare number keeps meaning what it meant: 3 (metres) becomes 3m before the switch
    for (const id of ["focus", "near", "far"]) {
      const el = $(id);
      el.value = bareAsWritten(el.value);
    }
  }
  st.units = units;
  press(["units-metric", "units-imperial"], `units-${units}`);
  $("unit-hint").textContent = units === "imperial"
    ? "A bare number is feet (as on the command line with --units ft); 10'6\", 6in, 3m are read as written."
    : "A bare number is millimetres (as on the command line): write 3m for three metres; 10ft, 10'6\" too.";
  $("focus").placeholder = units === "imperial" ? "10 · 10'6\" · 3m" : "3m · 10ft · 10'6\"";
}

function setCoc(value) {
  const custom = value !== "" && !COCS.includes(value);
  $("coc").value = custom ? "custom" : (value || DEFAULT_COC);
  $("coc-mm").value = custom ? value : "";
  $("field-coc-mm").hidden = !custom;
}

function addOption(sel, value, label) {
  if (![...sel.options].some((o) => o.value === value)) sel.append(new Option(label || value, value));
  sel.value = value;
}

function fillLenses(lenses, wanted) {
  const sel = $("lens");
  const cur = wanted || sel.value;
  sel.replaceChildren(...lenses.map((l) => {
    const f = l.efl_mm === null ? "" : ` — ${num(l.efl_mm, 1)} mm f/${num(l.f_number, 2)}`;
    return new Option(`${l.name}${f}`, l.slug);
  }));
  if (cur) {
    const hit = lenses.find((l) => norm(l.slug) === norm(cur) || norm(l.name) === norm(cur)
      || (l.aliases || []).some((a) => norm(a) === norm(cur)));
    if (hit) sel.value = hit.slug; else addOption(sel, cur);
  }
}

function applyState(q, serverUnits) {
  // the address's units, else the server's (the user config's units = "ft" starts the page in feet)
  const u = q.get("units") || (serverUnits === "ft" ? "imperial" : "metric");
  setUnits(u === "imperial" || u === "ft" ? "imperial" : "metric", false);
  setSolve(["fstop", "focus"].includes(q.get("solve")) ? q.get("solve") : "dof");
  const empty = ![...q.keys()].length;
  setLensMode(q.has("lens") ? "library" : "focal");
  if (q.has("lens")) addOption($("lens"), q.get("lens"));
  $("focal").value = q.get("focal") || (empty ? DEFAULTS.focal : "");
  for (const id of ["fstop", "tstop", "focus", "near", "far", "sensor-width", "sensor-height"]) {
    $(id).value = q.get(id) || (empty && DEFAULTS[id] ? DEFAULTS[id] : "");
  }
  fillCameras();
  fillSensors("");
  if (q.has("sensor-width") || q.has("sensor-height")) {
    $("sensor").value = "custom";
  } else if (q.has("sensor")) {
    const key = findSensor(q.get("sensor"));
    if (key) $("sensor").value = key; else addOption($("sensor"), q.get("sensor"));
    st.sensorAsked = key && window.PhysOnset && PhysOnset.cameraNameNote(q.get("sensor"), SENSORS)
      ? { name: q.get("sensor"), key } : null;
  } else {
    $("sensor").value = DEFAULT_SENSOR;
  }
  $("custom-sensor").hidden = $("sensor").value !== "custom";
  const chosen = SENSORS.find((x) => x.key === $("sensor").value);
  if (chosen && chosen.camera) { // the camera picker shows the format's camera, the format picker its formats
    const key = chosen.key;
    $("camera").value = cameraOf(chosen);
    fillSensors("");
    $("sensor").value = key;
  }
  const sq = q.get("squeeze") || "1";
  if ([...$("squeeze").options].some((o) => Number(o.value) === Number(sq))) {
    $("squeeze").value = [...$("squeeze").options].find((o) => Number(o.value) === Number(sq)).value;
  } else {
    addOption($("squeeze"), sq, `${sq}×`);
  }
  setCoc(q.get("coc") || "");
}

function wire() {
  const form = $("setup");
  form.addEventListener("input", (e) => {
    if (e.target.id === "sensor-search") fillSensors(e.target.value);
    else if (e.target.id === "camera") fillSensors(val("sensor-search"));
    else schedule();
  });
  form.addEventListener("change", (e) => {
    if (e.target.id === "sensor") sensorChanged();
    else if (e.target.id === "camera") fillSensors(val("sensor-search"));
    else if (e.target.id === "squeeze") {
      st.squeezeFromFormat = false; // the user's own choice, kept across formats
      $("squeeze-hint").hidden = true;
      update();
    }
    else if (e.target.id === "coc") {
      $("field-coc-mm").hidden = $("coc").value !== "custom";
      update();
    } else if (e.target.tagName === "SELECT") update();
  });
  form.addEventListener("submit", (e) => { e.preventDefault(); update(); });
  $("lensmode-focal").addEventListener("click", () => { setLensMode("focal"); update(); });
  $("lensmode-library").addEventListener("click", () => { setLensMode("library"); update(); });
  for (const mode of ["dof", "fstop", "focus"]) {
    $(`solve-${mode}`).addEventListener("click", () => { setSolve(mode); update(); });
  }
  $("units-metric").addEventListener("click", () => { setUnits("metric", true); update(); });
  $("units-imperial").addEventListener("click", () => { setUnits("imperial", true); update(); });
  $("theme").addEventListener("click", () => {
    const t = document.documentElement.dataset.theme === "light" ? "dark" : "light";
    document.documentElement.dataset.theme = t;
    try { localStorage.setItem("physcam-theme", t); } catch (e) { /* private mode */ }
  });
  $("share").addEventListener("click", async () => {
    const input = $("share-url");
    input.value = location.href;
    try {
      await navigator.clipboard.writeText(input.value);
    } catch (e) {
      input.select();
      document.execCommand("copy");
    }
    $("share").textContent = "copied";
    setTimeout(() => { $("share").textContent = "copy link"; }, 1500);
  });
  for (const kind of ["pointermove", "pointerdown"]) $("dof-wrap").addEventListener(kind, chartCursor);
  $("dof-wrap").addEventListener("pointerleave", () => { $("dof-cursor").hidden = true; });
  for (const img of [$("dof-chart"), $("diagram")]) {
    img.addEventListener("error", () => { img.hidden = true; });
  }
}

function offerCoc() {
  // first use: the common conventions offered by name (d/1500 gives 0.0207 mm on Super 35 where a puller's
  // app says 0.025); the choice is kept on this phone
  let chosen = null;
  try { chosen = localStorage.getItem("physcam-coc"); } catch (e) { /* private mode */ }
  const q = new URLSearchParams(location.search);
  if (chosen && !q.has("coc")) setCoc(chosen);
  $("coc-first").hidden = !!chosen || q.has("coc");
  for (const b of $("coc-first").querySelectorAll("button")) {
    b.addEventListener("click", () => {
      setCoc(b.dataset.coc);
      try { localStorage.setItem("physcam-coc", b.dataset.coc); } catch (e) { /* private mode */ }
      $("coc-first").hidden = true;
      update();
    });
  }
}

function registerWorker() {
  // the installable web app: sw.js keeps the page and the camera table (a secure context only:
  // localhost, 127.0.0.1 or HTTPS; docs/serve.md)
  if (!("serviceWorker" in navigator) || !window.isSecureContext) return;
  navigator.serviceWorker.register("/sw.js").then(() => navigator.serviceWorker.ready)
    .then(() => { document.body.dataset.worker = "ready"; })
    .catch(() => { document.body.dataset.worker = "failed"; });
}

async function start() {
  registerWorker();
  try {
    const t = localStorage.getItem("physcam-theme");
    if (t === "light" || t === "dark") document.documentElement.dataset.theme = t;
  } catch (e) { /* private mode */ }
  wire();
  const q = new URLSearchParams(location.search);
  let serverUnits = "m";
  try {
    const r = await fetch("/api/sensors"); // the camera table: from the server, or the worker's copy offline
    SENSORS = await r.json();
  } catch (e) {
    showMessage("the physcam server cannot be reached; is it still running?");
    return;
  }
  try { // the server's unit system (its user config); offline, the last one it said
    serverUnits = (await (await fetch("/api/health")).json()).units || "m";
    try { localStorage.setItem("physcam-server-units", serverUnits); } catch (e) { /* private mode */ }
  } catch (e) {
    try { serverUnits = localStorage.getItem("physcam-server-units") || "m"; } catch (e2) { /* private mode */ }
  }
  applyState(q, serverUnits);
  offerCoc();
  const lensesLoaded = fetch("/api/lenses").then((r) => r.json()).then((l) => fillLenses(l, q.get("lens")))
    .catch(() => {});
  if (st.lensmode === "library") await lensesLoaded;
  await update();
  document.body.dataset.ready = "1";
}

document.addEventListener("DOMContentLoaded", start);
