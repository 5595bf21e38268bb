// Runs the page's own solver (src/physcam/serve/static/onset.js) on setups read as JSON from standard
// input and writes one answer per setup as JSON. {"sensors": [...], "setups": [{query}, ...]}: the report,
// {"ok": true, "body": report} or {"ok": false, "body": {"error": sentence}}. {"calls": [[name, args...], ...]}:
// onset.js's function `name` on those arguments, {"ok": true, "body": result} or the refusal likewise.
"use strict";
const path = require("path");
const onset = require(path.join(process.argv[2], "onset.js"));

function call(fn) {
  try {
    return { ok: true, body: fn() };
  } catch (e) {
    if (e instanceof onset.ReportError) return { ok: false, body: { error: e.message } };
    throw e;
  }
}

let text = "";
process.stdin.setEncoding("utf8");
process.stdin.on("data", (chunk) => { text += chunk; });
process.stdin.on("end", () => {
  const job = JSON.parse(text);
  if (job.coc_conventions) onset.setCocConventions(job.coc_conventions);
  const inf = (x) => (x === "inf" ? Infinity : x);
  const answers = job.calls
    ? job.calls.map(([name, ...args]) => call(() => onset[name](...args.map(inf), job.sensors)))
    : job.setups.map((q) => onset.report(q, job.sensors));
  process.stdout.write(JSON.stringify(answers));
});
