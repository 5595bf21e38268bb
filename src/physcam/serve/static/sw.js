// physcam serve's service worker: the page, its scripts and the camera table kept in the browser, so
// that the page opens and computes the on-set report (onset.js) with the server switched off.
// Network first (an update of physcam is seen as soon as the server answers), the cache when it
// does not. A navigation with a setup in its URL (?focal=35&fstop=4...) is answered by the cached
// page, which reads the setup from its own URL. Charts, real lenses and diagrams need the server.
"use strict";

// v2: v1 kept any page opened in a tab (a report's JSON, a chart's SVG) as "/", the page itself (round 22);
// the new name empties every v1 cache when this worker takes over
const CACHE = "physcam-v2";
const SHELL = ["/", "/static/app.js", "/static/onset.js", "/static/tools.js", "/static/app.css",
  "/static/icon.svg", "/static/icon-192.png", "/manifest.webmanifest", "/api/sensors"];
// answers kept whenever they come: the catalogues the page needs to compute alone
const KEPT = ["/api/sensors", "/api/lenses"];

self.addEventListener("install", (event) => {
  event.waitUntil(caches.open(CACHE).then((c) => c.addAll(SHELL)).then(() => self.skipWaiting()));
});

self.addEventListener("activate", (event) => {
  event.waitUntil(caches.keys()
    .then((keys) => Promise.all(keys.filter((k) => k !== CACHE).map((k) => caches.delete(k))))
    .then(() => self.clients.claim()));
});

function keep(request) {
  const url = new URL(request.url);
  if (url.origin !== self.location.origin || request.method !== "GET") return null;
  if (url.pathname === "/") return "/"; // the page, whatever setup its URL carries; never another page opened
  if (request.mode === "navigate") return null; // a report's JSON or a chart opened in a tab: the server's
  if (SHELL.includes(url.pathname) || KEPT.includes(url.pathname)) return url.pathname;
  return null;
}

self.addEventListener("fetch", (event) => {
  const key = keep(event.request);
  if (key === null) return; // the server's own answers (reports, charts, lenses): no cache
  event.respondWith((async () => {
    const cache = await caches.open(CACHE);
    try {
      const fresh = await fetch(event.request);
      if (fresh.ok) await cache.put(key, fresh.clone());
      return fresh;
    } catch (e) {
      const hit = await cache.match(key);
      if (hit) return hit;
      throw e;
    }
  })());
});
