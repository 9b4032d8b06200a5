#!/usr/bin/env python3
"""Opens the built documentation site in headless Chromium and checks every internal link and image.

    python3 scripts/check_site.py [SITE]            # default build/site (made by scripts/docs.sh)
    python3 scripts/check_site.py --screenshot index.html:front.png --screenshot tutorials/01-first-run.html:t1.png

The site is served on a local port; Chromium loads a checker page that opens every HTML page of the MkDocs
site (and the API reference's index) in an iframe, waits for it to load, and reports each <img> that did not
load (naturalWidth 0) and each internal link whose target does not answer 200 or whose #fragment names no
element of the target page. Exit status: 0 all good, 1 broken links or images (listed), 77 when chromium is
not installed (the ctest then reports "skipped").
"""

import argparse
import functools
import http.server
import json
import os
import shutil
import socketserver
import subprocess
import sys
import tempfile
import threading

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SKIP = 77

CHECKER = r"""<!doctype html><html><head><meta charset="utf-8"><title>check</title></head><body>
<pre id="result">running</pre>
<img src="/_hold" alt="" style="display:none">
<script>
const pages = %PAGES%;
const cache = new Map();
async function fetchDoc(url) {
  if (!cache.has(url)) {
    cache.set(url, (async () => {
      try {
        const r = await fetch(url);
        if (!r.ok) return {status: r.status, ids: null};
        const type = r.headers.get('content-type') || '';
        if (!type.includes('html')) return {status: r.status, ids: null};
        const d = new DOMParser().parseFromString(await r.text(), 'text/html');
        const ids = new Set();
        d.querySelectorAll('[id],[name]').forEach(e => { if (e.id) ids.add(e.id); if (e.getAttribute('name')) ids.add(e.getAttribute('name')); });
        return {status: r.status, ids};
      } catch (e) { return {status: 'error ' + e, ids: null}; }
    })());
  }
  return cache.get(url);
}
function load(page) {
  return new Promise(resolve => {
    const f = document.createElement('iframe');
    f.style.width = '1200px'; f.style.height = '800px';
    const timer = setTimeout(() => resolve({frame: f, timeout: true}), 20000);
    f.onload = () => { clearTimeout(timer); resolve({frame: f, timeout: false}); };
    f.src = page;
    document.body.appendChild(f);
  });
}
(async () => {
  const out = {pages: 0, links: 0, images: 0, broken_links: [], broken_images: [], timeouts: []};
  for (const page of pages) {
    const {frame, timeout} = await load(page);
    out.pages++;
    if (timeout) { out.timeouts.push(page); frame.remove(); continue; }
    const doc = frame.contentDocument;
    for (const img of doc.querySelectorAll('img')) {
      out.images++;
      if (!img.complete || img.naturalWidth === 0) out.broken_images.push(page + ': ' + img.getAttribute('src'));
    }
    for (const a of doc.querySelectorAll('a[href]')) {
      const raw = a.getAttribute('href');
      if (/^(mailto:|javascript:)/.test(raw)) continue;
      const url = new URL(raw, frame.contentWindow.location.href);
      if (url.origin !== location.origin) continue;          // external: not checked (no network)
      out.links++;
      const target = url.origin + url.pathname;
      const got = await fetchDoc(target);
      if (got.status !== 200) { out.broken_links.push(page + ': ' + raw + ' (' + got.status + ')'); continue; }
      const frag = decodeURIComponent(url.hash.slice(1));
      if (frag && got.ids && !got.ids.has(frag)) out.broken_links.push(page + ': ' + raw + ' (no #' + frag + ')');
    }
    frame.remove();
  }
  document.getElementById('result').textContent = 'RESULT ' + JSON.stringify(out);
  await fetch('/_result', {method: 'POST', body: JSON.stringify(out)});
})();
</script></body></html>
"""


def chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        p = shutil.which(name)
        if p:
            return p
    return None


def chromium_args(exe, profile):
    return [exe, "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
            "--disable-component-update", "--no-first-run", f"--user-data-dir={profile}", "--hide-scrollbars"]


RESULT = {"body": None, "done": threading.Event()}
GIF = bytes.fromhex("47494638396101000100800000000000ffffff21f90401000000002c00000000010001000002024401003b")


class QuietHandler(http.server.SimpleHTTPRequestHandler):
    """Serves the site; /_result receives the checker's report, and /_hold (an image of the checker page)
    answers only then, so that the page's load event, and with it chromium --dump-dom, waits for the checks."""

    def log_message(self, *a):
        pass

    def do_POST(self):
        if self.path == "/_result":
            RESULT["body"] = self.rfile.read(int(self.headers.get("Content-Length", "0"))).decode()
            RESULT["done"].set()
        self.send_response(204)
        self.end_headers()

    def do_GET(self):
        if self.path == "/_hold":
            RESULT["done"].wait(timeout=500)
            self.send_response(200)
            self.send_header("Content-Type", "image/gif")
            self.send_header("Content-Length", str(len(GIF)))
            self.end_headers()
            self.wfile.write(GIF)
            return
        super().do_GET()


def serve(directory):
    handler = functools.partial(QuietHandler, directory=directory)
    httpd = socketserver.ThreadingTCPServer(("127.0.0.1", 0), handler)
    httpd.daemon_threads = True
    threading.Thread(target=httpd.serve_forever, daemon=True).start()
    return httpd, httpd.server_address[1]


def site_pages(site):
    pages = []
    for dirpath, dirnames, files in os.walk(site):
        rel = os.path.relpath(dirpath, site)
        if rel.split(os.sep)[0] in ("api", "search", "css", "js", "fonts", "img"):
            dirnames[:] = []
            continue
        for f in files:
            if f.endswith(".html") and f != "_check.html" and f != "404.html":
                pages.append(os.path.normpath(os.path.join(rel, f)).replace(os.sep, "/"))
    if os.path.isfile(os.path.join(site, "api", "index.html")):
        pages.append("api/index.html")
    return sorted(pages)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("site", nargs="?", default=os.path.join(ROOT, "build", "site"))
    ap.add_argument("--screenshot", action="append", default=[], metavar="PAGE:PNG",
                    help="also save a screenshot of PAGE (relative to the site) to PNG")
    args = ap.parse_args()
    exe = chromium()
    if not exe:
        print("check_site: chromium not installed (bash scripts/install-deps.sh --with-docs); skipped")
        return SKIP
    site = os.path.abspath(args.site)
    if not os.path.isfile(os.path.join(site, "index.html")):
        print(f"check_site: {site}/index.html missing: build the site first (bash scripts/docs.sh)")
        return 1
    pages = site_pages(site)
    with open(os.path.join(site, "_check.html"), "w", encoding="utf-8") as f:
        f.write(CHECKER.replace("%PAGES%", json.dumps(["/" + p for p in pages])))
    httpd, port = serve(site)
    profile = tempfile.mkdtemp(prefix="shelldyn-chromium-")
    try:
        cmd = chromium_args(exe, profile) + ["--dump-dom", f"http://127.0.0.1:{port}/_check.html"]
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=600)
        if RESULT["body"] is None:
            print("check_site: the checker page did not finish; chromium said:\n" + p.stderr[-2000:])
            return 1
        r = json.loads(RESULT["body"])
        for shot in args.screenshot:
            page, png = shot.split(":", 1)
            subprocess.run(chromium_args(exe, profile) + ["--window-size=1280,900", f"--screenshot={os.path.abspath(png)}",
                                                          f"http://127.0.0.1:{port}/{page}"],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=120, check=True)
            print(f"check_site: screenshot of {page} -> {png}")
    finally:
        httpd.shutdown()
        shutil.rmtree(profile, ignore_errors=True)
        os.remove(os.path.join(site, "_check.html"))
    print(f"check_site: {r['pages']} pages, {r['links']} internal links, {r['images']} images checked in headless Chromium")
    bad = r["broken_links"] + r["broken_images"] + [t + ": did not load within 20 s" for t in r["timeouts"]]
    for b in r["broken_links"]:
        print("  broken link: " + b)
    for b in r["broken_images"]:
        print("  image not loaded: " + b)
    for t in r["timeouts"]:
        print("  page did not load: " + t)
    print("check_site: " + ("all links resolve and all images load" if not bad else f"{len(bad)} problem(s)"))
    return 0 if not bad else 1


if __name__ == "__main__":
    sys.exit(main())
