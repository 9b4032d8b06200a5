#!/usr/bin/env python3
"""Runs every command of the README and the tutorials verbatim, and counts them.

    python3 scripts/run_doc_commands.py            # README.md, then docs/tutorials/*.md in order
    python3 scripts/run_doc_commands.py --list     # print the blocks and their commands, run nothing
    python3 scripts/run_doc_commands.py docs/tutorials/03-comparing-integrators.md   # some files only

A fenced block marked ```bash is a runnable block: it is run as it stands, as one `bash -e -o pipefail`
script from the repository root, after the blocks before it in the same file (later blocks may use what
earlier ones wrote). Blocks marked otherwise (```sh, ```text, ```yaml, indented code) are illustrations
and are not run: commands that need a cluster, root or a program shelldyn does not depend on are written so.
A command is a non-empty, non-comment line of a runnable block (a line continued with a backslash and a
here-document count as one). Exit status 0 when every block passed; the summary gives per-file counts.
"""

import argparse
import glob
import os
import re
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FENCE = re.compile(r"^```(\w*)\s*$")


def blocks(path):
    """(first line number, language, text) of every fenced block of a Markdown file."""
    out, lang, start, buf = [], None, 0, []
    with open(path, encoding="utf-8") as f:
        for n, line in enumerate(f, 1):
            m = FENCE.match(line.rstrip("\n"))
            if lang is None and m:
                lang, start, buf = m.group(1), n, []
            elif lang is not None and line.rstrip("\n") == "```":
                out.append((start, lang, "".join(buf)))
                lang = None
            elif lang is not None:
                buf.append(line)
    return out


def commands(text):
    """The commands of a block: continuation lines and here-documents are joined to their command."""
    cmds, cur, heredoc = [], "", None
    for line in text.splitlines():
        if heredoc is not None:
            cur += "\n" + line
            if line.strip() == heredoc:
                cmds.append(cur)
                cur, heredoc = "", None
            continue
        s = line.strip()
        if not cur and (not s or s.startswith("#")):
            continue
        cur = cur + "\n" + line if cur else line
        m = re.search(r"<<-?\s*'?\"?(\w+)'?\"?", line)
        if m:
            heredoc = m.group(1)
            continue
        if s.endswith("\\"):
            continue
        cmds.append(cur)
        cur = ""
    if cur:
        cmds.append(cur)
    return cmds


def default_files():
    return [os.path.join(ROOT, "README.md")] + sorted(glob.glob(os.path.join(ROOT, "docs", "tutorials", "*.md")))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("files", nargs="*", help="Markdown files (default: README.md and docs/tutorials/*.md)")
    ap.add_argument("--list", action="store_true", help="list the runnable blocks and commands; run nothing")
    ap.add_argument("--timeout", type=float, default=3600, help="seconds per block (default 3600)")
    ap.add_argument("--log", default=os.path.join(ROOT, "build", "doc-commands.log"), help="output of every block")
    args = ap.parse_args()
    files = [os.path.abspath(f) for f in args.files] or default_files()
    if not args.list:
        os.makedirs(os.path.dirname(args.log), exist_ok=True)
        open(args.log, "w").close()
    totals = {"blocks": 0, "commands": 0, "failed": 0}
    rows = []
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    for path in files:
        rel = os.path.relpath(path, ROOT)
        runnable = [(n, text) for n, lang, text in blocks(path) if lang == "bash"]
        n_cmds, failed, seconds = 0, 0, 0.0
        for line, text in runnable:
            cmds = commands(text)
            n_cmds += len(cmds)
            if args.list:
                print(f"{rel}:{line}: {len(cmds)} command(s)")
                for c in cmds:
                    print("    " + c.replace("\n", "\n    "))
                continue
            t0 = time.time()
            try:
                p = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", text], cwd=ROOT, env=env,
                                   stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=args.timeout)
                rc, out = p.returncode, p.stdout
            except subprocess.TimeoutExpired as e:
                rc, out = "timeout", (e.stdout or b"").decode() if isinstance(e.stdout, bytes) else (e.stdout or "")
            dt = time.time() - t0
            seconds += dt
            with open(args.log, "a", encoding="utf-8") as f:
                f.write(f"==== {rel}:{line} (exit {rc}, {dt:.1f} s)\n{text}---- output\n{out}\n")
            status = "ok" if rc == 0 else f"FAILED (exit {rc})"
            print(f"{rel}:{line}: {len(cmds)} command(s), {dt:.1f} s: {status}", flush=True)
            if rc != 0:
                failed += 1
                print("    " + "\n    ".join(out.strip().splitlines()[-8:]), flush=True)
        totals["blocks"] += len(runnable)
        totals["commands"] += n_cmds
        totals["failed"] += failed
        rows.append((rel, len(runnable), n_cmds, failed, seconds))
    print()
    print(f"{'file':50} {'blocks':>6} {'commands':>8} {'failed':>6} {'wall s':>7}")
    for rel, b, c, f, s in rows:
        print(f"{rel:50} {b:6d} {c:8d} {f:6d} {s:7.0f}")
    print(f"{'total':50} {totals['blocks']:6d} {totals['commands']:8d} {totals['failed']:6d}")
    if args.list:
        return 0
    print(("all blocks passed" if totals["failed"] == 0 else f"{totals['failed']} block(s) FAILED") + f"; log: {args.log}")
    return 0 if totals["failed"] == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
