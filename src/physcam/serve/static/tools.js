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

  function afterReport(d) {
    last = d;
    frame(d);
    diopters(d);
    splitFocus();
  }

  function wire() {
    for (const id of ["split-near", "split-far"]) el(id).addEventListener("input", splitFocus);
    el("exposure").addEventListener("input", exposure);
    el("exposure").addEventListener("change", exposure);
    el("exposure").addEventListener("submit", (e) => e.preventDefault());
    exposure();
  }

  window.PhysTools = { afterReport };
  document.addEventListener("DOMContentLoaded", wire);
})();
