// physcam's on-set lens report in the page: the thin-lens (practical) and datasheet (technical) models
// of physcam.onset.report.solve_report, step for step, so that the page answers with the laptop off.
// A setup is the query /api/report takes (the CLI's flags without dashes, values as typed: "2m",
// "10'6\"", "inf", "hyperfocal", "d/1500"); the answer has the keys and numbers of `physcam report
// --json` (tests/serve/test_onset_js.py compares them on 10,000 random setups to 1e-9 relative).
// Real prescriptions (lens=...) need the server: solveReport refuses them with a sentence.
// Formulas and their sources: physcam.optics.dof, physcam.optics.thinlens, physcam.onset.solvers.
// Lengths in mm; distances *_from_film_mm in front of the film plane, object distances from H1.
(function (root) {
  "use strict";

  class ReportError extends Error {}

  const fail = (msg) => { throw new ReportError(msg); };
  const HYPERFOCAL = "hyperfocal";
  const HYPERFOCAL_RTOL = 1e-6;
  const MIN_F_NUMBER = 0.5;
  const MAX_F_NUMBER = 4096.0;
  const MAX_DISTANCE_MM = 1.0e9;
  const WAVELENGTH_NM = 550.0;
  const AIRY_FACTOR = 2.44;
  const DBL_MIN = 2.2250738585072014e-308;

  // --- numbers and distances as typed (physcam.units.parse_distance, cli._common) -------------------
  const MM_PER_UNIT = { mm: 1.0, cm: 10.0, m: 1000.0, km: 1.0e6, in: 25.4, inch: 25.4, inches: 25.4, '"': 25.4,
    ft: 304.8, foot: 304.8, feet: 304.8, "'": 304.8, um: 1.0e-3, "µm": 1.0e-3 };
  const NUMBER = "[+-]?(?:\\d+(?:\\.\\d*)?|\\.\\d+)(?:[eE][+-]?\\d+)?";
  const SIMPLE = new RegExp(`^\\s*(${NUMBER})\\s*([a-zA-Zµ'"]*)\\s*$`);
  const INCHES = "(?:(\\d+(?:\\.\\d*)?)(?:\\s+(\\d+)/(\\d+))?|(\\d+)/(\\d+))";
  const FEET_INCHES = new RegExp(`^\\s*(?:(${NUMBER})\\s*(?:ft|feet|foot|'))?\\s*(?:${INCHES}\\s*(?:in|inch|inches|"))?\\s*$`);
  const FEET_BARE_INCHES = new RegExp(`^\\s*(${NUMBER})\\s*(?:ft|feet|foot|')\\s*${INCHES}\\s*$`);
  const INFINITY_WORDS = ["inf", "infinity", "∞"];

  function toMm(value, unit) {
    const key = unit === "'" || unit === '"' ? unit : unit.toLowerCase();
    if (!(key in MM_PER_UNIT)) fail(`unknown unit '${unit}'; use one of mm, cm, m, in, ft`);
    return value * MM_PER_UNIT[key];
  }

  function inches(whole, num, den, fnum, fden) {
    let v = whole !== undefined ? Number(whole) : 0.0;
    for (const [n, d] of [[num, den], [fnum, fden]]) {
      if (n !== undefined) {
        if (parseInt(d, 10) === 0) fail(`a fraction of an inch needs a denominator above 0, got ${n}/${d}`);
        v += parseInt(n, 10) / parseInt(d, 10);
      }
    }
    return v;
  }

  // typographic foot marks (U+2019, U+2018, U+2032) as ', inch marks (U+201D, U+201C, U+2033) as ", and two
  // foot marks as an inch mark (6'' or 6’’ is 6 inches): physcam.units.plain_marks
  function plainMarks(text) {
    return text.replace(/[\u2019\u2018\u2032]/g, "'").replace(/[\u201d\u201c\u2033]/g, '"').replace(/''/g, '"');
  }

  function parseDistance(text, name = "distance", allowInf = false) {
    if (typeof text === "number") return text;
    const s = String(text).trim();
    const t = plainMarks(s); // refusals quote what was typed, s
    if (INFINITY_WORDS.includes(s.toLowerCase())) {
      if (allowInf) return Infinity;
      fail(`${name} must be finite, got '${s}'`);
    }
    let v;
    let m = /['"/]/.test(t) || /\d\s*(ft|feet|foot)\s*\d/.test(t) ? FEET_INCHES.exec(t) : null;
    m = m || (t.includes("/") ? FEET_BARE_INCHES.exec(t) : null);
    if (m && (m[1] !== undefined || m.slice(2).some((g) => g !== undefined))) {
      v = Math.abs(Number(m[1] || 0.0)) * 304.8 + inches(...m.slice(2, 7)) * 25.4;
      if (t.startsWith("-")) v = -v;
    } else {
      m = SIMPLE.exec(t);
      if (!m) fail(`cannot read ${name} '${s}': write a number with an optional unit, e.g. 3m, 10ft, 6in, 450mm`);
      v = toMm(Number(m[1]), m[2] || "mm");
    }
    if (Number.isNaN(v) || (!Number.isFinite(v) && !allowInf)) fail(`${name} must be a finite number, got '${text}'`);
    return v;
  }

  // Python's float(text): a decimal number (underscores between digits), inf, infinity or nan; undefined
  // where Python raises ValueError
  const PY_DECIMAL = /^[+-]?(\d(_?\d)*(\.(\d(_?\d)*)?)?|\.\d(_?\d)*)([eE][+-]?\d(_?\d)*)?$/;

  function pyFloat(text) {
    const t = String(text).trim().toLowerCase();
    const w = /^([+-]?)(inf|infinity|nan)$/.exec(t);
    if (w) return w[2] === "nan" ? NaN : (w[1] === "-" ? -Infinity : Infinity);
    return PY_DECIMAL.test(t) ? Number(t.replace(/_/g, "")) : undefined;
  }

  function number(text, name) {
    // cli._common.number: a finite, normal float
    const v = pyFloat(text);
    if (v === undefined) fail(`${name} must be a number, got '${text}'`);
    if (!Number.isFinite(v)) fail(`${name} must be a finite number, got '${text}'`);
    if (v !== 0 && Math.abs(v) < DBL_MIN) fail(`${name} is out of range, got '${text}'`);
    return v;
  }

  function positive(name, v, unit = "mm", allowInf = false) {
    const ok = allowInf ? v > 0 : v > 0 && Number.isFinite(v);
    if (!ok) fail(`${name} must be above 0${allowInf ? "" : " and finite"}, got ${v}${unit ? " " + unit : ""}`);
    return v;
  }

  function out(v, what, allowInf = false) {
    if (Number.isNaN(v) || (!Number.isFinite(v) && !allowInf)) fail(`${what} is not a finite number; check the inputs`);
    return v;
  }

  function requireFNumber(name, v) {
    positive(name, v, "");
    if (!(MIN_F_NUMBER <= v && v <= MAX_F_NUMBER)) fail(`${name} ${v} is out of range (f/${MIN_F_NUMBER} to f/${MAX_F_NUMBER})`);
    return v;
  }

  // the focal lengths of camera lenses, mm (physcam.optics.thinlens.require_focal_length)
  const MIN_FOCAL_LENGTH_MM = 1.0;
  const MAX_FOCAL_LENGTH_MM = 1.0e5;

  function requireFocalLength(f, name = "focal length") {
    positive(name, f);
    if (f > MAX_FOCAL_LENGTH_MM) fail(`${name} ${f} mm is beyond any camera lens; give it in mm (e.g. --focal 50)`);
    if (f < MIN_FOCAL_LENGTH_MM) fail(`${name} ${f} mm is shorter than any camera lens (at least ${MIN_FOCAL_LENGTH_MM} mm); give it in mm (e.g. --focal 50)`);
    return f;
  }

  function requireDistance(name, v) {
    positive(name, v);
    if (v > MAX_DISTANCE_MM) fail(`${name} ${v} mm is beyond 1000 km; for a subject at infinity use a far limit of inf`);
    return v;
  }

  // --- circles of confusion (physcam.optics.coc) --------------------------------------------------
  const COC_CONVENTIONS = {};
  const COC_ALIASES = {};

  function setCocConventions(list) {
    // [{name, description, kind: "diagonal" | "fixed", value}] as `physcam coc --json` lists them
    for (const k of Object.keys(COC_CONVENTIONS)) delete COC_CONVENTIONS[k];
    for (const k of Object.keys(COC_ALIASES)) delete COC_ALIASES[k];
    for (const c of list) {
      COC_CONVENTIONS[c.name] = c;
      for (const a of c.aliases || []) COC_ALIASES[a] = c.name;
    }
  }
  setCocConventions([
    { name: "d/1500", kind: "diagonal", value: 1500.0, aliases: ["zeiss", "modern"] },
    { name: "d/1000", kind: "diagonal", value: 1000.0, aliases: ["traditional"] },
    { name: "d/1730", kind: "diagonal", value: 1730.0, aliases: [] },
    { name: "cine", kind: "fixed", value: 0.025, aliases: ["acm", "0.025", "s35", "super35"] },
    { name: "full-frame", kind: "fixed", value: 0.03, aliases: ["ff", "fullframe", "0.03"] },
    { name: "16mm", kind: "fixed", value: 0.015, aliases: ["s16", "0.015"] },
  ]);

  // the circles of confusion a person may give, mm (physcam.optics.coc.MIN_COC_MM, MAX_COC_MM, require_coc)
  const MIN_COC_MM = 0.001;
  const MAX_COC_MM = 1.0;

  function requireCoc(v) {
    if (!Number.isFinite(v)) fail(`circle of confusion must be a finite number, got ${v}`);
    if (v <= 0) fail(`circle of confusion must be greater than 0 mm, got ${v}`);
    if (!(v >= MIN_COC_MM && v <= MAX_COC_MM)) {
      fail(`circle of confusion ${v} mm is out of range: give ${MIN_COC_MM} mm (1 um) to ${MAX_COC_MM} mm (0.025 mm is Super 35 cine), or a convention such as d/1500`);
    }
    return v;
  }

  function cocRule(conv, w, h) {
    return conv.kind === "diagonal" ? Math.hypot(w, h) / conv.value : conv.value;
  }

  function parseCoc(text) {
    // physcam.optics.coc.parse_coc: a number is mm; a length with a unit is read; a name stays text
    if (text === undefined || text === null) return null;
    const name = String(text).trim().toLowerCase();
    if (name in COC_CONVENTIONS || name in COC_ALIASES) return String(text).trim(); // "16mm" is a name
    const f = pyFloat(text);
    if (f !== undefined) return requireCoc(f);
    const t = String(text).trim();
    if (t && /^[0-9.+-]/.test(t) && !t.includes("/")) return requireCoc(parseDistance(t, "circle of confusion"));
    return text;
  }

  function circleOfConfusion(w, h, convention) {
    if (convention === null || convention === undefined) convention = "d/1500";
    if (typeof convention === "number") return [requireCoc(convention), "user"];
    let key = String(convention).trim().toLowerCase();
    key = COC_ALIASES[key] || key;
    if (key in COC_CONVENTIONS) return [cocRule(COC_CONVENTIONS[key], w, h), key];
    const v = pyFloat(key.endsWith("mm") ? key.slice(0, -2) : key);
    if (v === undefined) {
      fail(`unknown circle-of-confusion convention '${convention}'; use one of ${Object.keys(COC_CONVENTIONS).join(", ")} or a value in mm`);
    }
    return [requireCoc(v), "user"];
  }

  function namedCoc(w, h, given, c, name) {
    // a value equal to a named convention for this sensor keeps that convention's name
    if (name !== "user" || typeof given !== "number") return [c, name];
    for (const key of Object.keys(COC_CONVENTIONS)) {
      const v = cocRule(COC_CONVENTIONS[key], w, h);
      if (Math.abs(c - v) <= 1e-6 * v) return [c, key];
    }
    return [c, name];
  }

  // --- sensors (physcam.onset.sensors.find_sensor) -------------------------------------------------
  const norm = (s) => String(s).toLowerCase().replace(/[^a-z0-9]+/g, "");
  const FAMILY_NAMES = { alexa: "ALEXA", arri: "ALEXA", arriflex: "ALEXA" };

  function findSensor(table, name) {
    const key = norm(name);
    if (!key) fail("the sensor name is empty. `physcam sensors` lists them all");
    if (key in FAMILY_NAMES) fail(`'${name}' names a camera family, not one sensor`);
    for (const s of table) {
      if ([s.key, s.name, ...(s.aliases || [])].some((l) => norm(l) === key)) return s;
    }
    if (table.ask && table.ask(key)) fail(table.ask(key));
    return fail(`unknown sensor '${name}'. \`physcam sensors\` lists them all`);
  }

  // physcam.optics.sensors.camera_name_note: a bare camera name ("ALEXA 35") that a sensors.csv row (a gate,
  // no camera) answers is that camera's full sensor; say which format of the camera table it is and how to
  // name another (the CLI's and the server's report note), "" for any other name
  function cameraNameNote(name, table) {
    const key = norm(name);
    const gate = table.find((s) => !s.camera && [s.key, s.name, ...(s.aliases || [])].some((l) => norm(l) === key));
    if (!gate || name.trim() === gate.key) return "";
    const cams = new Map(); // "ARRI ALEXA 35" -> its formats, in table order (sensors.cameras)
    for (const s of table) if (s.camera) cams.set(`${s.maker} ${s.camera}`, [...(cams.get(`${s.maker} ${s.camera}`) || []), s]);
    let best = null;
    for (const [full, rows] of cams) {
      const short = norm(rows[0].camera);
      const same = rows.filter((r) => Math.abs(r.width_mm - gate.width_mm) <= 0.011 && Math.abs(r.height_mm - gate.height_mm) <= 0.011);
      if (rows.length > 1 && same.length && norm(full).includes(key)) {
        const rank = [key !== short && key !== norm(full) ? 1 : 0, norm(gate.name).includes(norm(full)) ? 0 : 1, full.length];
        const before = (a, b) => a[0] - b[0] || a[1] - b[1] || a[2] - b[2];
        if (best === null || before(rank, best.rank) < 0 || (before(rank, best.rank) === 0 && full < best.full)) {
          best = { rank, full, fmt: same[0] };
        }
      }
    }
    if (best === null) return "";
    const rows = cams.get(best.full), f = best.fmt, g = (x) => String(Number(x.toPrecision(6))); // Python's :g
    return `'${name}' is the ${best.full}'s full sensor, its ${f.format} (${g(f.width_mm)} x ${g(f.height_mm)} mm); the camera `
      + `records in ${rows.length} formats and the crop sets the depth of field and the field of view: name another `
      + `as the sensor, e.g. '${rows[1].aliases[0]}' (\`physcam sensors "${best.full}"\` lists them)`;
  }

  function customSensor(w, h) {
    if (!Number.isFinite(w) || !Number.isFinite(h)) fail("sensor width and height must be finite numbers");
    if (!(0.5 <= w && w <= 1000 && 0.5 <= h && h <= 1000)) {
      fail(`sensor width and height must lie between 0.5 and 1000 mm, got ${w} x ${h} mm`);
    }
    if (Math.max(w / h, h / w) > 20) fail(`a ${w} x ${h} mm sensor is too narrow; physcam accepts up to 20:1`);
    return { key: "custom", name: `custom ${w} x ${h} mm`, width_mm: w, height_mm: h, photosite_pitch_um: null };
  }

  // --- the request (physcam.onset.request.ReportRequest and the CLI's argument types) --------------
  const FOCUS_WORDS = [HYPERFOCAL, "hyper", "hyperfocal distance"];
  const KNOWN = ["focal", "fstop", "tstop", "focus", "near", "far", "sensor", "sensor-width", "sensor-height",
    "squeeze", "coc", "model", "h1", "h2", "pupil", "reference", "flange", "sensor-front", "lens-length",
    "pupil-fraction", "units"];
  // physcam's one rule for a bare scene distance (cli._common.BARE_RULE): a focus, near or far typed as a bare
  // number is millimetres, or feet under units=ft; lengths inside the camera are always millimetres
  const BARE_NUMBER = /^\s*[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?\s*$/;

  function scene(text, name, allowInf, units) {
    const v = parseDistance(text, name, allowInf);
    return units === "ft" && BARE_NUMBER.test(String(text)) ? Number(String(text).trim()) * 304.8 : v;
  }

  function readFocus(text, units) {
    const t = String(text).trim().toLowerCase();
    if (FOCUS_WORDS.includes(t)) return HYPERFOCAL;
    if (INFINITY_WORDS.includes(t)) return Infinity;
    return scene(text, "focus distance", false, units);
  }

  function request(q, sensors, defaultSensor = "Super 35") {
    if ("lens" in q) fail("a real lens prescription needs the physcam server (it traces the lens): reconnect");
    for (const k of Object.keys(q)) if (!KNOWN.includes(k)) fail(`unknown parameter '${k}'`);
    const opt = (k, read) => (k in q ? read(q[k]) : null);
    const units = q.units === undefined ? "m" : q.units;
    if (!["m", "ft"].includes(units)) fail(`units: invalid choice '${units}' (choose from 'm', 'ft')`);
    const r = {
      focal: opt("focal", (t) => parseDistance(t, "focal length")),
      fstop: opt("fstop", (t) => number(t, "f-stop")),
      tstop: opt("tstop", (t) => number(t, "T-stop")),
      focus: opt("focus", (t) => readFocus(t, units)),
      near: opt("near", (t) => scene(t, "near limit", false, units)),
      far: opt("far", (t) => scene(t, "far limit", true, units)),
      squeeze: "squeeze" in q ? number(q.squeeze, "squeeze") : 1.0,
      coc: opt("coc", parseCoc),
      model: q.model === undefined ? "practical" : q.model,
      h1: opt("h1", (t) => parseDistance(t, "H1 offset")),
      h2: opt("h2", (t) => parseDistance(t, "H2 offset")),
      pupil: opt("pupil", (t) => parseDistance(t, "entrance pupil offset")),
      reference: q.reference === undefined ? "film" : q.reference,
      flange: opt("flange", (t) => parseDistance(t, "flange focal distance")),
      sensorFront: opt("sensor-front", (t) => parseDistance(t, "sensor-to-lens-front distance")),
      lensLength: opt("lens-length", (t) => parseDistance(t, "lens length")),
      pupilFraction: opt("pupil-fraction", (t) => number(t, "pupil fraction")),
    };
    if (!["practical", "technical"].includes(r.model)) fail(`model: invalid choice '${r.model}'`);
    if (!["film", "flange"].includes(r.reference)) fail(`reference: invalid choice '${r.reference}'`);
    const sw = opt("sensor-width", (t) => parseDistance(t, "sensor width"));
    const sh = opt("sensor-height", (t) => parseDistance(t, "sensor height"));
    // cli.report.solve_from_args
    if (r.focal === null) fail("give the focal length, e.g. --focal 50, or a lens with --lens NAME");
    if (r.pupilFraction !== null && r.sensorFront === null) {
      fail("--pupil-fraction places the tape-measure pupil estimate: it needs --sensor-front and --lens-length");
    }
    if (r.pupilFraction === null) r.pupilFraction = 0.4;
    // cli._common.resolve_sensor
    if ("sensor" in q && (sw !== null || sh !== null)) fail("give either --sensor NAME or --sensor-width/--sensor-height, not both");
    if ("sensor" in q) {
      r.sensor = findSensor(sensors, q.sensor);
      r.sensorNote = cameraNameNote(q.sensor, sensors);
    } else if (sw !== null || sh !== null) {
      if (sw === null || sh === null) fail("give both --sensor-width and --sensor-height");
      r.sensor = customSensor(sw, sh);
    } else {
      r.sensor = findSensor(sensors, defaultSensor);
      r.sensorDefaulted = true;
    }
    checkRequest(r);
    return r;
  }

  function checkRequest(r) {
    const w = r.sensor.width_mm, h = r.sensor.height_mm;
    if (r.sensorFront !== null && r.lensLength === null) fail("the tape-measured sensor-to-lens-front distance needs the lens length too (--lens-length)");
    if (r.lensLength !== null && r.sensorFront === null) fail("the lens length is used only with the sensor-to-lens-front distance (--sensor-front)");
    for (const [name, v] of [["sensor width", w], ["sensor height", h]]) {
      if (!(v > 0 && v <= 1000)) fail(`${name} must lie between 0 and 1000 mm, got ${v}`);
    }
    positive("anamorphic squeeze", r.squeeze, "");
    if (!(r.squeeze >= 0.1 && r.squeeze <= 10)) fail(`anamorphic squeeze must lie between 0.1 and 10, got ${r.squeeze}`);
    requireFocalLength(r.focal);
    if (r.fstop !== null) requireFNumber("f-stop", r.fstop);
    if (r.tstop !== null) requireFNumber("T-stop", r.tstop);
    const limits = r.near !== null || r.far !== null;
    if (r.focus === HYPERFOCAL && (limits || r.fstop === null)) {
      fail("focus at the hyperfocal distance needs the f-stop (--fstop), and no measured near/far limits");
    }
    if (r.focus !== null && r.focus !== HYPERFOCAL && r.focus !== Infinity) requireDistance("focus distance", r.focus);
    if (r.near !== null) requireDistance("near limit", r.near);
    if (r.far !== null) {
      if (Number.isNaN(r.far) || r.far <= 0) fail(`far limit must be a positive distance (or inf), got ${r.far}`);
      if (Number.isFinite(r.far)) requireDistance("far limit", r.far);
    }
    if (r.near !== null && r.far !== null && !(r.near < r.far)) fail(`near limit ${r.near} mm must be closer than far limit ${r.far} mm`);
    if (r.reference === "flange") {
      if (r.flange === null) fail("a flange reference needs the flange focal distance (e.g. 52 mm for PL, 44 mm for LPL)");
      positive("flange focal distance", r.flange);
    }
    if (r.model === "practical" && (r.h1 !== null || r.h2 !== null)) fail("principal-plane offsets (--h1/--h2) belong to the technical model: add --model technical");
    if (r.pupil !== null && r.sensorFront !== null) fail("give the entrance pupil either as a datasheet offset (--pupil) or as a tape-measure estimate, not both");
    if (r.model === "technical" && (r.h1 === null || r.h2 === null)) fail("the technical model needs --h1 and --h2 (principal planes from the reference plane)");
  }

  // --- optics (physcam.optics.dof and thinlens, exact thin-lens forms about H1) ------------------------
  const hOf = (f, a, b) => (f / a) * (f / b); // f^2 / (a b) without underflow

  function hyperfocalDistance(f, n, c) {
    positive("focal length", f); positive("f-number", n, ""); positive("circle of confusion", c);
    return out(hOf(f, n, c) + f, "the hyperfocal distance");
  }

  function dofLimits(f, n, c, s) {
    positive("focal length", f); positive("f-number", n, ""); positive("circle of confusion", c);
    positive("focus distance", s, "mm", true);
    if (s <= f) fail("focus distance is at or inside the focal length: no real image forms");
    const h = out(hOf(f, n, c), "the hyperfocal parameter");
    const near = h / (1.0 + (h - f) / s);
    const denom = h - (s - f);
    const far = denom > HYPERFOCAL_RTOL * (h + f) ? h * s / denom : Infinity;
    return [out(near, "the near limit"), out(far, "the far limit", true)];
  }

  function imageDistance(f, s) {
    positive("focal length", f); positive("object distance", s, "mm", true);
    if (s <= f) fail("the subject is at or inside the focal length: no real image forms on the film");
    return out(f / (1.0 - f / s), "the image distance");
  }

  function objectDistanceForMarked(f, mark) {
    positive("focal length", f); positive("focus mark", mark, "mm", true);
    if (mark === Infinity) return Infinity;
    const L = mark;
    const disc = L * L - 4.0 * L * f;
    if (disc < -1e-9 * L * L || L <= 0) {
      fail(`focus mark ${mark} mm is closer than this lens can focus: the closest mark for a ${f} mm thin lens is ${4 * f} mm from the film plane (4f)`);
    }
    return out(0.5 * (L + Math.sqrt(Math.max(disc, 0.0))), "the object distance", true);
  }

  function hpFromNear(f, s, n) {
    positive("focal length", f); positive("focus distance", s, "mm", true);
    if (n <= 0 || !Number.isFinite(n)) fail("the near limit must be in front of the lens (> 0) and finite");
    if (n >= s) fail("the near limit must be closer than the focus distance");
    return out(n * (1.0 - f / s) / (1.0 - n / s), "the hyperfocal parameter");
  }

  function hpFromFar(f, s, F) {
    positive("focal length", f); positive("focus distance", s); positive("far limit", F, "mm", true);
    if (F <= s) fail("the far limit must be beyond the focus distance");
    if (!Number.isFinite(F)) fail("an infinite far limit only says the focus is at or beyond the hyperfocal distance; give a near limit");
    return out((s - f) / (1.0 - s / F), "the hyperfocal parameter");
  }

  function focusForDofLimits(n, F) {
    positive("near limit", n); positive("far limit", F, "mm", true);
    if (F <= n) fail("need 0 < near limit < far limit");
    return out(Number.isFinite(F) ? 2.0 * n / (1.0 + n / F) : 2.0 * n, "the focus distance");
  }

  function fNumberForDof(f, c, h) {
    positive("focal length", f); positive("circle of confusion", c); positive("hyperfocal parameter", h);
    return out(hOf(f, c, h), "the f-number");
  }

  function cocForDof(f, n, h) {
    positive("focal length", f); positive("f-number", n, ""); positive("hyperfocal parameter", h);
    return out(hOf(f, n, h), "the circle of confusion");
  }

  function stopsBetween(e, m) {
    positive("effective f-number", e, ""); positive("marked f-number", m, "");
    return out(2.0 * (Math.log2(e) - Math.log2(m)), "the stops between");
  }

  const finiteOrNull = (v) => (v === null || v === undefined || !Number.isFinite(v) ? null : v);

  // --- principal planes (physcam.onset.solvers.PrincipalPlanes) ------------------------------------------
  function planesOf(f, h1, h2) {
    const p = { f, h1, h2 };
    p.h1At = (s) => (h1 !== null ? h1 : (s === Infinity ? f : imageDistance(f, s)));
    p.sForMark = (mark) => {
      if (h1 === null) return mark === Infinity ? Infinity : objectDistanceForMarked(f, mark);
      const s = mark - h1;
      if (s <= f) fail(`focus mark ${mark} mm puts the subject ${s} mm in front of H1, at or inside the ${f} mm focal length: no real image`);
      return s;
    };
    p.markForS = (s) => s + p.h1At(s);
    p.toH1 = (d, s) => d - p.h1At(s);
    return p;
  }

  function bracketFocus(near, far, planes) {
    const f = planes.f;
    let p = f;
    for (let i = 0; i < 100; i++) {
      const n = near - p, F = far - p;
      if (n <= f) fail("the measured near limit is inside the focal length");
      const s = focusForDofLimits(n, F);
      const pNew = planes.h1At(s);
      if (Math.abs(pNew - p) < 1e-10 * Math.max(1.0, p)) return s;
      p = pNew;
    }
    return fail("could not solve the focus distance from the near/far bracket");
  }

  function oneLimitFocus(near, far, hp, planes) {
    const f = planes.f;
    let p = f;
    for (let i = 0; i < 100; i++) {
      let s;
      if (near !== null) {
        const n = near - p;
        if (!(n > 0 && n < hp)) fail("the near limit lies beyond the hyperfocal parameter f^2/(N c) (focus at infinity): no focus gives it; check the near limit, f-stop and CoC");
        s = n * (hp - f) / (hp - n);
      } else {
        const F = far - p;
        s = F * (hp + f) / (hp + F);
      }
      const pNew = planes.h1At(s);
      if (Math.abs(pNew - p) < 1e-10 * Math.max(1.0, p)) return s;
      p = pNew;
    }
    return fail("could not solve the focus distance from the measured limit");
  }

  function solveFocus(r, fstop, planes, c) {
    const f = planes.f, solved = {}, notes = [];
    let mark = r.focus;
    if (mark === HYPERFOCAL) {
      mark = planes.markForS(hyperfocalDistance(f, fstop, c));
      solved.focus = HYPERFOCAL;
      notes.push(`focus at the hyperfocal distance: mark ${mark.toPrecision(6)} mm from the film`);
    } else if (mark === null) {
      let s;
      if (r.near !== null && r.far !== null) s = bracketFocus(r.near, r.far, planes);
      else if (fstop !== null && (r.near !== null || r.far !== null)) s = oneLimitFocus(r.near, r.far, f * f / (fstop * c), planes);
      else fail("give a focus distance (--focus), or measured near and far limits (--near, --far), or one limit with the f-stop");
      mark = planes.markForS(s);
      solved.focus_from_film_mm = mark;
    }
    const s = planes.sForMark(mark);
    const sImg = s === Infinity ? f : imageDistance(f, s);
    if (s === Infinity && !("focus_from_film_mm" in solved) && r.far !== null && Number.isFinite(r.far)) {
      fail("with the focus at infinity the far limit is infinite; a finite far limit is impossible");
    }
    return { mark, s, sImg, solved, notes };
  }

  function hyperfocalParameters(planes, s, near, far) {
    let hpNear = null, hpFar = null;
    if (near !== null && s === Infinity) {
      hpNear = planes.toH1(near, s);
      if (!(hpNear > 0)) fail("the near limit must lie in front of the lens");
    } else if (near !== null) {
      hpNear = hpFromNear(planes.f, s, planes.toH1(near, s));
    }
    if (far !== null && Number.isFinite(far)) hpFar = hpFromFar(planes.f, s, planes.toH1(far, s));
    if (hpNear === null && hpFar === null) fail("an infinite far limit alone cannot give the aperture; measure the near limit too");
    return [hpNear, hpFar];
  }

  function farCheck(planes, s, n, c, far) {
    const pred = dofLimits(planes.f, n, c, s)[1] + planes.h1At(s);
    const bothInf = pred === Infinity && far === Infinity;
    const err = bothInf ? 0.0 : (pred === Infinity || far === Infinity ? null : pred - far);
    return { far_predicted_from_film_mm: finiteOrNull(pred), far_error_mm: err };
  }

  function invertLimits(r, planes, foc, c, cocName) {
    const { near, far } = r, s = foc.s, solved = {}, notes = [];
    let N = r.fstop;
    const oneLimit = "focus_from_film_mm" in foc.solved && (near === null || far === null);
    const split = "focus_from_film_mm" in foc.solved && near !== null && far !== null;
    if (split && N !== null) {
      // split focus with the stop given: the stop and CoC are kept; the stop the asked limits need beside them
      const h = hpFromNear(planes.f, s, planes.toH1(near, s));
      const need = fNumberForDof(planes.f, c, h);
      solved.fstop_needed = need;
      solved.fstop_needed_stops_over_given = stopsBetween(need, N);
      notes.push(N < need ? `split focus with the stop given: f/${N.toPrecision(3)} holds less than the asked limits; they need f/${need.toPrecision(3)}`
        : `split focus: f/${N.toPrecision(3)} holds the asked limits; they need f/${need.toPrecision(3)}`);
    } else if ((near !== null || far !== null) && !oneLimit) {
      const [hpNear, hpFar] = hyperfocalParameters(planes, s, near, far);
      const hp = hpNear !== null ? hpNear : hpFar;
      if (hpNear !== null && hpFar !== null) {
        solved.hyperfocal_parameter_from_near_mm = hpNear;
        solved.hyperfocal_parameter_from_far_mm = hpFar;
        solved.consistency = Math.abs(hpFar - hpNear) / hpNear;
        // over-determined only: the focus and stop solved from both limits agree by construction (the CLI's note too)
        if (!split) notes.push(`near and far limits agree to ${(100 * solved.consistency).toFixed(1)}% in the hyperfocal parameter`);
      }
      if (N === null || r.coc !== null) {
        const marked = N;
        N = fNumberForDof(planes.f, c, hp);
        solved.fstop = N;
        if (marked !== null) solved.fstop_drift_stops = stopsBetween(N, marked);
      } else {
        c = cocForDof(planes.f, N, hp);
        cocName = "solved";
        solved.coc_mm = c;
      }
      if (far !== null && hpNear !== null) Object.assign(solved, farCheck(planes, s, N, c, far));
    }
    if (N === null) fail("give the f-stop (--fstop) or a measured near/far limit to solve it");
    for (const [name, v] of [["f-stop", N], ["circle of confusion", c]]) {
      if (!(Number.isFinite(v) && v > 0)) fail(`the measured limits give an impossible ${name} (${v}); check --near, --far and --focus`);
    }
    if (N < MIN_F_NUMBER) fail(`the measured limits need f/${N.toPrecision(3)}, faster than any lens in air can be (f/${MIN_F_NUMBER}); check --near, --far, --focus and the CoC`);
    return { fstop: N, c, cocName, solved, notes };
  }

  function dofBlock(f, n, c, s, h1At) {
    const [near, far] = dofLimits(f, n, c, s);
    const H = hyperfocalDistance(f, n, c);
    const total = far - near;
    return {
      coc_mm: c, hyperfocal_mm: H, hyperfocal_from_film_mm: H + h1At(H), near_mm: near, far_mm: finiteOrNull(far),
      total_mm: finiteOrNull(total), near_from_film_mm: near + h1At(s), far_from_film_mm: finiteOrNull(far + h1At(s)),
      far_is_infinite: far === Infinity,
    };
  }

  const fovDeg = (size, f) => 2.0 * Math.atan(size / (2.0 * f)) * (180.0 / Math.PI);

  // --- the report (physcam.onset.report.solve_report and LensReport.to_dict) ---------------------------
  function solveRequest(r) {
    const sensor = r.sensor, w = sensor.width_mm, h = sensor.height_mm, sq = r.squeeze;
    const ref = r.reference === "flange" ? r.flange : 0.0;
    const at = (v) => (v === null ? null : ref + v);
    const technical = r.model === "technical";
    const planes = technical ? planesOf(r.focal, at(r.h1), at(r.h2)) : planesOf(r.focal, null, null);
    const f = planes.f;
    let [c, cocName] = circleOfConfusion(w, h, r.coc);
    [c, cocName] = namedCoc(w, h, r.coc, c, cocName);
    const foc = solveFocus(r, r.fstop, planes, c);
    const ap = invertLimits(r, planes, foc, c, cocName);
    const solved = { ...foc.solved, ...ap.solved };
    const notes = [...foc.notes, ...ap.notes];
    if (r.tstop !== null) {
      solved.tstop_drift_stops = stopsBetween(ap.fstop, r.tstop);
      if (r.tstop < ap.fstop - 1e-9) notes.push("the T-stop is faster than the f-stop: a T-stop is never below the f-number");
    }
    const N = ap.fstop, s = foc.s;
    const dof = dofBlock(f, N, ap.c, s, planes.h1At);
    let dofH = null;
    const aspect = 1.0 / sq;
    if (sq !== 1.0) {
      dofH = dofBlock(f, N, ap.c / aspect, s, planes.h1At);
      notes.push(`anamorphic ${sq}x: a defocused point is ${aspect.toPrecision(3)} as wide as tall in the desqueezed picture, so the horizontal limits take the CoC c / ${aspect.toPrecision(3)} = ${(ap.c / aspect).toPrecision(4)} mm`);
    }
    let h1Film, h2Film, err = 0.0;
    if (!technical) {
      h1Film = h2Film = foc.sImg;
    } else {
      h1Film = planes.h1;
      h2Film = planes.h2;
      if (h2Film <= 0) fail(`H2 must lie in front of the film plane, got ${h2Film} mm; check --h2 and --reference`);
      err = h2Film - foc.sImg;
      if (Math.abs(err) > 1e-6) notes.push(`with these principal planes the sharp image lies ${Math.abs(err).toFixed(3)} mm ${err > 0 ? "in front of" : "behind"} the film plane`);
    }
    let pupil = null, pupilSrc = "unknown";
    if (r.pupil !== null) {
      pupil = at(r.pupil); pupilSrc = "datasheet";
    } else if (r.sensorFront !== null) {
      const front = positive("sensor-to-lens-front distance", r.sensorFront);
      const length = positive("lens length", r.lensLength);
      const frac = r.pupilFraction;
      if (!Number.isFinite(frac)) fail("pupil fraction must be a finite number");
      if (!(frac >= 0 && frac <= 1)) fail(`pupil fraction must lie between 0 and 1 of the lens length, got ${frac}`);
      if (length > front) fail(`lens length ${length} mm is longer than the film-to-lens-front distance ${front} mm; measure the film mark to the front of the lens`);
      pupil = front - frac * length;
      pupilSrc = `estimate: ${frac} of the lens length behind its front`;
    } else if (!technical) {
      pupil = h1Film; pupilSrc = "thin lens: at the principal plane";
    } else {
      notes.push("no entrance pupil: give --pupil (technical) or --sensor-front and --lens-length");
    }
    const m = s === Infinity ? 0.0 : -f / (s - f);
    const wd = w * sq;
    const pin = h2Film;
    const d = {
      schema: "physcam.lens_report", version: 3, units: { length: "mm", angle: "degree" },
      model: r.model, lens: null, focal_length_mm: f, fstop: N, tstop: r.tstop, aperture_diameter_mm: f / N,
      fstop_at_focus: N, squeeze: sq,
      sensor: { key: sensor.key, name: sensor.name, width_mm: w, height_mm: h, diagonal_mm: Math.hypot(w, h),
        photosite_pitch_mm: sensor.photosite_pitch_um === null || sensor.photosite_pitch_um === undefined
          ? null : sensor.photosite_pitch_um * 1e-3 },
      coc_mm: ap.c, coc_convention: ap.cocName,
      focus_from_film_mm: finiteOrNull(foc.mark), focus_is_infinite: foc.mark === Infinity,
      object_distance_mm: finiteOrNull(s), image_distance_mm: foc.sImg, h1_from_film_mm: h1Film,
      h2_from_film_mm: h2Film, reference_plane: r.reference,
      flange_focal_distance_mm: r.reference === "flange" ? r.flange : null, focus_error_mm: err, magnification: m,
      frame_at_focus: frameAtFocus(w, h, sq, m, s),
      dof, dof_horizontal: dofH, split_focus: null,
      pinhole: { focal_length_mm: pin, squeeze: sq },
      fov_deg: {
        infinity: { horizontal: fovDeg(wd, f), vertical: fovDeg(h, f), diagonal: fovDeg(Math.hypot(wd, h), f) },
        focus: { horizontal: fovDeg(wd, pin), vertical: fovDeg(h, pin), diagonal: fovDeg(Math.hypot(wd, h), pin) },
        real: null, real_differs: false,
      },
      entrance_pupil_from_film_mm: pupil, stop_from_film_mm: technical ? null : h1Film, dof_aspect: aspect,
      entrance_pupil_source: pupilSrc, pivot_camera_space_mm: pupil === null ? null : [0.0, 0.0, -pupil],
      solved, measured: {}, notes,
    };
    if (r.near !== null) d.measured.near_from_film_mm = r.near;
    if (r.far !== null) d.measured.far_from_film_mm = finiteOrNull(r.far);
    if (solved.fstop_needed !== undefined) { // LensReport.split_focus
      const need = solved.fstop_needed;
      d.split_focus = { near_asked_from_film_mm: r.near, far_asked_from_film_mm: finiteOrNull(r.far),
        fstop_given: N, fstop_needed: need, holds: N >= need * (1 - 1e-9) };
    }
    const pivot = pupil === null ? null : [0.0, 0.0, -pupil]; // one pupil for both meridians
    d.entrance_pupils = { horizontal_from_film_mm: pupil, vertical_from_film_mm: pupil,
      separation_mm: pupil === null ? null : 0.0, pan_pivot_camera_space_mm: pivot, tilt_pivot_camera_space_mm: pivot };
    d.diffraction = diffraction(d, sensor);
    notes.push(diffractionNote(d));
    if (r.sensorNote) notes.push(r.sensorNote); // a bare camera name: which format it is (cli.report)
    if (r.sensorDefaulted) notes.push(`no --sensor given: ${sensor.name}, ${w} x ${h} mm`);
    checkFinite(d, "");
    return d;
  }

  // the picture's width and height in the plane of sharp focus: the (desqueezed) gate over |m|
  // (physcam.onset.framing.frame_at_focus)
  function frameAtFocus(w, h, sq, m, s) {
    if (m === 0.0 || s === Infinity) return null;
    const fw = w * sq / Math.abs(m), fh = h / Math.abs(m);
    return { width_mm: fw, height_mm: fh, diagonal_mm: Math.hypot(fw, fh), distance_from_h1_mm: s };
  }

  function diffraction(d, sensor) {
    const lam = WAVELENGTH_NM, N = d.fstop;
    const nw = N * (1.0 + Math.abs(d.magnification));
    const airy = AIRY_FACTOR * lam * 1e-6 * nw;
    const k = nw / N;
    const pMm = sensor.photosite_pitch_um === null || sensor.photosite_pitch_um === undefined ? null : sensor.photosite_pitch_um * 1e-3;
    const fstopFor = (size) => size / (AIRY_FACTOR * lam * 1e-6 * k);
    return {
      wavelength_nm: lam, working_f_number: nw, airy_diameter_mm: airy, coc_mm: d.coc_mm, airy_to_coc: airy / d.coc_mm,
      exceeds_coc: airy > d.coc_mm, fstop_airy_exceeds_coc: fstopFor(d.coc_mm), photosite_pitch_mm: pMm,
      airy_in_photosites: pMm === null ? null : airy / pMm,
      fstop_airy_exceeds_two_photosites: pMm === null ? null : fstopFor(2 * pMm),
    };
  }

  function diffractionNote(d) {
    const x = d.diffraction;
    return `diffraction (${x.wavelength_nm} nm): Airy disk ${(x.airy_diameter_mm * 1000).toFixed(1)} µm across at f/${d.fstop.toPrecision(3)}; it ${x.exceeds_coc ? "exceeds" : "would exceed"} the CoC past f/${x.fstop_airy_exceeds_coc.toPrecision(3)}`;
  }

  function checkFinite(x, path) {
    if (typeof x === "number" && !Number.isFinite(x)) fail(`the report's ${path} came out ${x}; check the inputs`);
    if (x && typeof x === "object") for (const [k, v] of Object.entries(x)) checkFinite(v, path ? `${path}.${k}` : k);
  }

  // solveReport(query, sensors): the report document for the setup, or throws ReportError
  function solveReport(query, sensors, defaultSensor) {
    return solveRequest(request(query, sensors, defaultSensor));
  }

  // report(query, sensors): {ok, body} like the server's answer (body.error on refusal)
  function report(query, sensors, defaultSensor) {
    try {
      return { ok: true, body: solveReport(query, sensors, defaultSensor) };
    } catch (e) {
      if (e instanceof ReportError) return { ok: false, body: { error: e.message } };
      throw e;
    }
  }

  // --- beyond depth of field (physcam.onset.exposure, .diopter, .split_focus) ----------------------------
  const ND_STOP_DENSITY = 0.3;

  function exposureTime(angle, fps) {
    positive("shutter angle", angle, "degrees");
    if (angle > 360.0) fail(`a shutter angle is at most 360 degrees (open all the frame), got ${angle}`);
    return (angle / 360.0) / positive("frame rate", fps, "fps");
  }

  function setting(x) {
    // {fps, shutter_deg, tstop, ei, nd}, checked as ExposureSetting is
    const v = { fps: 24.0, shutter_deg: 180.0, tstop: 2.8, ei: 800.0, nd: 0.0, ...x };
    exposureTime(v.shutter_deg, v.fps);
    requireFNumber("T-stop", v.tstop);
    positive("exposure index", v.ei, "");
    if (!Number.isFinite(v.nd) || v.nd < 0) fail(`an ND's optical density is 0 or more (0.3 per stop), got ${v.nd}`);
    return { ...v, exposure_time_s: exposureTime(v.shutter_deg, v.fps) };
  }

  function exposureStops(a, b) {
    a = setting(a); b = setting(b);
    const parts = { time: Math.log2(b.exposure_time_s / a.exposure_time_s), ei: Math.log2(b.ei / a.ei),
      tstop: 0.0 - 2.0 * Math.log2(b.tstop / a.tstop), nd: (a.nd - b.nd) / ND_STOP_DENSITY };
    return { stops: parts.time + parts.ei + parts.tstop + parts.nd, parts };
  }

  function compensate(a, b, control = "tstop") {
    const delta = exposureStops(a, b).stops;
    b = setting(b);
    if (control === "tstop") return setting({ ...b, tstop: b.tstop * 2.0 ** (delta / 2.0) });
    if (control === "nd") {
      const nd = b.nd + delta * ND_STOP_DENSITY;
      if (nd < -1e-12) fail(`the new setting is ${(-delta).toFixed(2)} stops darker: no ND can give light back; open the T-stop or raise the EI`);
      return setting({ ...b, nd: Math.max(nd, 0.0) });
    }
    if (control === "ei") return setting({ ...b, ei: b.ei * 2.0 ** -delta });
    if (control === "shutter") {
      const t = b.exposure_time_s * 2.0 ** -delta;
      const angle = 360.0 * t * b.fps;
      if (angle > 360.0 + 1e-9) fail(`${t} s per frame at ${b.fps} fps needs a ${angle.toFixed(1)} degree shutter: more than the whole frame (360)`);
      return setting({ ...b, shutter_deg: angle });
    }
    return fail(`compensate with tstop, nd, ei or shutter, not '${control}'`);
  }

  function closeUp(f, n, c, mark, p) {
    // a +p diopter in contact with a thin lens at its principal plane (physcam.onset.diopter.close_up)
    requireFocalLength(f); positive("f-stop", n, ""); requireCoc(c);
    positive("diopter", p, "dioptres");
    if (p > 20.0) fail(`+${p} dioptres is a 50 mm magnifier, not a close-up lens; give the power in dioptres`);
    const s = objectDistanceForMarked(f, mark);
    const sImg = s === Infinity ? f : imageDistance(f, s);
    const power = p / 1000.0;
    const fc = 1.0 / (1.0 / f + power);
    const sd = 1.0 / ((s === Infinity ? 0.0 : 1.0 / s) + power);
    const nc = n * fc / f;
    const [near, far] = dofLimits(fc, nc, c, sd);
    const farFilm = far + sImg;
    return { diopter: p, focal_length_mm: fc, f_number: nc, subject_from_lens_mm: sd, subject_from_film_mm: sd + sImg,
      near_from_film_mm: near + sImg, far_from_film_mm: finiteOrNull(farFilm),
      depth_of_field_mm: finiteOrNull(farFilm - (near + sImg)), magnification: -sImg / sd };
  }

  function splitFocus(query, sensors) {
    // "focus here, at this stop": the report's own inverse solve with the near and far subjects and no stop;
    // with a stop given, that stop's limits at the mark beside it (physcam.onset.split_focus.split_focus)
    if (!("near" in query) || !("far" in query)) fail("split focus needs the near and the far subject");
    const q = { ...query };
    delete q.fstop; delete q.focus; delete q.tstop;
    const need = solveReport(q, sensors);
    let given = null;
    if ("fstop" in query) {
      const g = { ...query, focus: String(need.focus_from_film_mm), coc: String(need.coc_mm) };
      delete g.near; delete g.far;
      given = solveReport(g, sensors);
    }
    return { focus_from_film_mm: need.focus_from_film_mm, fstop_needed: need.fstop, coc_mm: need.coc_mm,
      coc_convention: need.coc_convention, near_from_film_mm: need.measured.near_from_film_mm,
      far_from_film_mm: need.measured.far_from_film_mm, fstop_given: given && given.fstop,
      given_holds: given && given.fstop >= need.fstop * (1 - 1e-9),
      given_near_from_film_mm: given && given.dof.near_from_film_mm,
      given_far_from_film_mm: given && given.dof.far_from_film_mm };
  }

  const api = { ReportError, solveReport, report, plainMarks, parseDistance, exposureStops, compensate, closeUp, splitFocus, parseCoc, circleOfConfusion, setCocConventions,
    findSensor, cameraNameNote, hyperfocalDistance, dofLimits, imageDistance, objectDistanceForMarked, stopsBetween, fovDeg,
    HYPERFOCAL, COC_CONVENTIONS };
  root.PhysOnset = api;
  if (typeof module !== "undefined" && module.exports) module.exports = api;
})(typeof globalThis !== "undefined" ? globalThis : this);
