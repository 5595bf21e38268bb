// physcam serve: what a focus puller asks beyond depth of field, computed in the page by onset.js (so it
// works with the laptop off): the frame at the subject, split focus ("focus here, at this stop"), close-up
// lenses and exposure in stops. app.js calls PhysTools.afterReport(report) after each answer; lengths are
// written by app.js's fmtLen (metres or feet and inches, as the switch says).
"use strict";

(function () {
  const el = (id) => document.getElementById(id);
  let last = null;

  function setupQuery() {
    // the page's current setup as /api/report's query (app.js apiParams), lens-free
    const q = Object.fromEntries(apiParams());
    delete q.lens;
    if (!q.focal && last) q.focal = String(last.focal_length_mm);
    return q;
  }

  function frame(d) {
    const out = el("out-frame");
    const f = d.frame_at_focus;
    out.dataset.width = f ? String(f.width_mm) : "";
    out.dataset.height = f ? String(f.height_mm) : "";
    out.textContent = f ? `${fmtLen(f.width_mm)} × ${fmtLen(f.height_mm)}` : "focused at infinity: no finite frame";
  }

  function splitFocus() {
    const out = el("split-answer");
    const near = el("split-near").value.trim(), far = el("split-far").value.trim();
    if (!near || !far) {
      out.textContent = "Give the near and the far subject: the page says where to focus and at what stop.";
      delete out.dataset.focus;
      return;
    }
    const q = setupQuery();
    q.near = withUnit(near);
    q.far = withUnit(far);
    delete q.focus;
    try {
      const a = PhysOnset.splitFocus(q, SENSORS);
      out.dataset.focus = String(a.focus_from_film_mm);
      out.dataset.fstop = String(a.fstop_needed);
      let text = `focus at ${fmtLen(a.focus_from_film_mm)}, stop f/${a.fstop_needed.toFixed(1)} or deeper `
        + `(CoC ${a.coc_mm.toFixed(4)} mm, ${a.coc_convention})`;
      if (a.fstop_given !== null) {
        text += a.given_holds ? ` · f/${num(a.fstop_given, 2)} holds both`
          : ` · at f/${num(a.fstop_given, 2)} only ${fmtLen(a.given_near_from_film_mm)} – ${fmtLen(a.given_far_from_film_mm)} is sharp`;
      }
      out.textContent = text;
    } catch (e) {
      delete out.dataset.focus;
      out.textContent = e.message;
    }
  }

  function diopters(d) {
    const body = el("diopters").tBodies[0];
    const rows = [0.5, 1, 2, 3].map((p) => {
      const tr = document.createElement("tr");
      tr.dataset.diopter = String(p);
      const label = document.createElement("td");
      label.textContent = `+${p}`;
      tr.append(label);
      let r = null;
      try {
        const mark = d.focus_from_film_mm === null ? Infinity : d.focus_from_film_mm;
        r = PhysOnset.closeUp(d.focal_length_mm, d.fstop, d.coc_mm, mark, p);
      } catch (e) {
        const td = document.createElement("td");
        td.colSpan = 4;
        td.className = "err";
        td.textContent = "n/a";
        td.title = e.message;
        tr.append(td);
        return tr;
      }
      for (const mm of [r.subject_from_film_mm, r.near_from_film_mm, r.far_from_film_mm, r.depth_of_field_mm]) {
        const td = document.createElement("td");
        showLen(td, mm);
        tr.append(td);
      }
      return tr;
    });
    body.replaceChildren(...rows);
  }

  function exposure() {
    const out = el("exposure-answer");
    const read = (id) => {
      const t = el(id).value.trim().replace(/^[tT]/, "");
      return t === "" ? null : Number(t);
    };
    const keys = { fps: "fps", shutter_deg: "shutter", tstop: "tstop", ei: "ei", nd: "nd" };
    const now = {}, next = {};
    for (const [k, id] of Object.entries(keys)) {
      now[k] = read(`ex-${id}`);
      const v = read(`ex-to-${id}`);
      next[k] = v === null ? now[k] : v;
    }
    if (Object.values(now).some((v) => v === null || Number.isNaN(v)) || Object.values(next).some(Number.isNaN)) {
      out.textContent = "the settings are numbers: fps, shutter angle in degrees, T-stop, EI, ND density (0.3 a stop)";
      return;
    }
    try {
      const change = PhysOnset.exposureStops(now, next);
      const how = el("ex-compensate").value;
      out.dataset.stops = String(change.stops);
      let text = `${change.stops >= 0 ? "+" : "−"}${Math.abs(change.stops).toFixed(2)} stops`;
      try {
        const fix = PhysOnset.compensate(now, next, how);
        out.dataset.fix = String({ tstop: fix.tstop, nd: fix.nd, ei: fix.ei, shutter: fix.shutter_deg }[how]);
        text += ` · the same exposure: ${{ tstop: `T${fix.tstop.toFixed(2)}`, nd: `ND ${fix.nd.toFixed(2)}`,
          ei: `EI ${Math.round(fix.ei)}`, shutter: `${fix.shutter_deg.toFixed(1)}° shutter` }[how]}`;
      } catch (e) {
        delete out.dataset.fix;
        text += ` · ${e.message}`;
      }
      out.textContent = text;
    } catch (e) {
      delete out.dataset.stops;
      out.textContent = e.message;
    }
  }

  // --- my lens set: one lens a line, "focal T-stop close-focus # name" (physcam.onset.lens_set) ----------
  const SET_LINE = /^\s*(\S+?)(?:\s*mm)?\s+[tT]?([\d.]+)(?:\s+([^#]+?))?\s*(?:#\s*(.*))?$/;

  function parseLensSet(text) {
    const lenses = [];
    String(text).split(/\r?\n/).forEach((raw, i) => {
      const line = raw.trim();
      if (!line || line.startsWith("#")) return;
      const m = SET_LINE.exec(line);
      if (!m) throw new Error(`line ${i + 1}: write a lens as 'focal T-stop close-focus', e.g. '50 T2 20in'`);
      const f = PhysOnset.parseDistance(m[1], "focal length");
      const t = Number(m[2]);
      if (!(t >= 0.5 && t <= 4096)) throw new Error(`line ${i + 1}: T-stop ${m[2]} is out of range`);
      if (!(f >= 1 && f <= 2000)) throw new Error(`line ${i + 1}: focal length ${f} mm is not a camera lens's`);
      const close = m[3] ? PhysOnset.parseDistance(m[3].trim(), "close focus") : null;
      lenses.push({ focal_length_mm: f, tstop: t, close_focus_mm: close, name: (m[4] || "").trim() });
    });
    return lenses;
  }

  let SET = [];
  const setLabel = (x) => `${num(x.focal_length_mm, 1)} mm T${num(x.tstop, 2)}${x.name ? ` ${x.name}` : ""}`;

  function loadSet(text) {
    const msg = el("lens-set-msg");
    try {
      SET = parseLensSet(text);
      msg.textContent = SET.length ? `${SET.length} lenses` : "One lens a line: focal length, T-stop wide open, close focus (from the film).";
      try { localStorage.setItem("physcam-lens-set", text); } catch (e) { /* private mode */ }
    } catch (e) {
      msg.textContent = e.message;
      return;
    }
    const sel = el("set-lens");
    const cur = sel.value;
    sel.replaceChildren(new Option("none: type the focal length", ""),
      ...SET.map((x, i) => new Option(setLabel(x), String(i))));
    sel.value = [...sel.options].some((o) => o.value === cur) ? cur : "";
    el("field-set").hidden = false;
  }

  function chooseSetLens() {
    const x = SET[Number(el("set-lens").value)];
    if (!x) return;
    el("focal").value = num(x.focal_length_mm, 2);
    if (!el("tstop").value) el("tstop").placeholder = `T${num(x.tstop, 2)} wide open`;
    schedule();
  }

  function setNotes(d) {
    // the chosen set lens: its T-stop and close focus against the setup
    const note = el("set-lens-note");
    const x = SET[Number(el("set-lens").value)];
    if (!x || Math.abs(x.focal_length_mm - d.focal_length_mm) > 1e-6) { note.textContent = ""; return; }
    const parts = [`T${num(x.tstop, 2)} wide open`];
    if (x.close_focus_mm !== null) parts.push(`close focus ${fmtLen(x.close_focus_mm)}`);
    if (d.tstop !== null && d.tstop < x.tstop - 1e-9) parts.push(`T${num(d.tstop, 2)} is faster than this lens opens`);
    if (x.close_focus_mm !== null && d.focus_from_film_mm !== null && d.focus_from_film_mm < x.close_focus_mm) {
      parts.push("the mark is closer than this lens focuses");
      note.dataset.tooClose = "1";
    } else {
      delete note.dataset.tooClose;
    }
    note.textContent = parts.join(" · ");
  }

  function setHyperfocal(d) {
    // each set lens's hyperfocal mark at the report's stop (or its own T-stop when slower) and CoC
    const sec = el("hyperfocal-section");
    sec.hidden = !SET.length;
    if (!SET.length) return;
    const q = setupQuery();
    const rows = SET.map((x) => {
      const tr = document.createElement("tr");
      const n = Math.max(d.fstop, x.tstop);
      const cell = { ...q, focal: String(x.focal_length_mm), fstop: String(n), focus: "hyperfocal", coc: String(d.coc_mm) };
      for (const k of ["near", "far", "tstop"]) delete cell[k];
      const r = PhysOnset.report(cell, SENSORS);
      const cells = [setLabel(x), `f/${num(n, 2)}`];
      tr.append(...cells.map((t) => { const td = document.createElement("td"); td.textContent = t; return td; }));
      for (const mm of r.ok ? [r.body.focus_from_film_mm, r.body.dof.near_from_film_mm] : [null, null]) {
        const td = document.createElement("td");
        if (r.ok) showLen(td, mm); else td.textContent = "n/a";
        tr.append(td);
      }
      return tr;
    });
    el("set-hyperfocal").tBodies[0].replaceChildren(...rows);
  }

  function afterReport(d) {
    last = d;
    frame(d);
    diopters(d);
    splitFocus();
    setNotes(d);
    setHyperfocal(d);
  }

  function wire() {
    let saved = "";
    try { saved = localStorage.getItem("physcam-lens-set") || ""; } catch (e) { /* private mode */ }
    el("lens-set-text").value = saved;
    if (saved) loadSet(saved);
    el("lens-set-text").addEventListener("input", (e) => { loadSet(e.target.value); if (last) setHyperfocal(last); });
    el("set-lens").addEventListener("change", chooseSetLens);
    for (const id of ["split-near", "split-far"]) el(id).addEventListener("input", splitFocus);
    el("exposure").addEventListener("input", exposure);
    el("exposure").addEventListener("change", exposure);
    el("exposure").addEventListener("submit", (e) => e.preventDefault());
    exposure();
  }

  window.PhysTools = { afterReport, parseLensSet };
  document.addEventListener("DOMContentLoaded", wire);
})();
