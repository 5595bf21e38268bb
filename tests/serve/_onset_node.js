// Runs the page's own solver (src/physcam/serve/static/onset.js) on setups read as JSON from standard
// input ({"sensors": [...], "setups": [{query}, ...]}) and writes one answer per setup as JSON:
// {"ok": true, "body": report} or {"ok": false, "body": {"error": sentence}}.
"use strict";
const path = require("path");
const onset = require(path.join(process.argv[2], "onset.js"));

let text = "";
process.stdin.setEncoding("utf8");
process.stdin.on("data", (chunk) => { text += chunk; });
process.stdin.on("end", () => {
  const job = JSON.parse(text);
  if (job.coc_conventions) onset.setCocConventions(job.coc_conventions);
  const answers = job.setups.map((q) => onset.report(q, job.sensors));
  process.stdout.write(JSON.stringify(answers));
});
