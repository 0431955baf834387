#!/usr/bin/env python3
"""Renders every RIB case of the bad-input corpus (manifest.json) with the
command-line renderer and checks that each is handled cleanly:

- expect "error": a non-zero exit status that is not a signal, and stderr
  exactly one line holding the case's message;
- expect "render": exit status 0, the image written, and stderr empty or one
  warning line holding the message;
- never "Segmentation", "core dumped", "Aborted" or "terminate called" on
  stderr, and no core file left in the working folder (each case runs in a
  fresh temporary folder), and no case running past its time limit.

  python3 tests/bad_input/run_corpus.py build/micropoly-render [--markdown OUT.md] [CASE.rib ...]

Cases marked known_failure are run and reported (XFAIL, or XPASS once they
pass) and do not change the exit status. --markdown writes a table of every
case: what it checks and the message it got.
"""

import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
CRASH_WORDS = ("Segmentation", "core dumped", "Aborted", "terminate called", "AddressSanitizer", "runtime error:")
DEFAULT_TIMEOUT_S = 60


COMPILER_SUMMARY = re.compile(r"^\d+ (error|warning)s? generated\.$")


def run_case(cli, case):
    """(problems, exit status or description, stderr, seconds) of one case."""
    work = tempfile.mkdtemp(prefix="mp-bad-input-")
    try:
        out = os.path.join(work, "out.png")
        started = time.perf_counter()
        try:
            proc = subprocess.run([cli, os.path.join(HERE, case["file"]), "-o", out], cwd=work,
                                  capture_output=True, timeout=case.get("timeout_s", DEFAULT_TIMEOUT_S))
        except subprocess.TimeoutExpired:
            return [f"ran past {case.get('timeout_s', DEFAULT_TIMEOUT_S)} s"], "timeout", "", \
                time.perf_counter() - started
        seconds = time.perf_counter() - started
        err = proc.stderr.decode("utf-8", "replace")
        # PoCL's compiler prints its clang summary ("1 error generated.")
        # straight to the process's stderr; that line is not the product's.
        lines = [line for line in err.splitlines() if line.strip() and not COMPILER_SUMMARY.match(line)]
        problems = []
        code = proc.returncode
        if code < 0:
            problems.append(f"killed by signal {signal.Signals(-code).name}")
        for word in CRASH_WORDS:
            if word in err:
                problems.append(f"stderr holds {word!r}")
        if any(name.startswith("core") for name in os.listdir(work)):
            problems.append("left a core file")
        if case["expect"] == "error":
            if code == 0:
                problems.append("exit status 0: the input was accepted")
            if len(lines) != 1:
                problems.append(f"stderr has {len(lines)} lines, not one")
            if case["message"] not in err:
                problems.append(f"stderr lacks {case['message']!r}")
        else:
            if code != 0:
                problems.append(f"exit status {code}")
            if code == 0 and not os.path.exists(out):
                problems.append("no image was written")
            if case["message"]:
                if len(lines) != 1 or case["message"] not in lines[0] or "warning" not in lines[0]:
                    problems.append(f"stderr is not one warning holding {case['message']!r}")
            elif lines:
                problems.append(f"unexpected stderr ({len(lines)} lines)")
        return problems, code, err, seconds
    finally:
        shutil.rmtree(work, ignore_errors=True)


def main():
    ap = argparse.ArgumentParser(description="Runs the bad-input corpus through micropoly-render.")
    ap.add_argument("cli")
    ap.add_argument("cases", nargs="*", help="only these files of the manifest")
    ap.add_argument("--markdown", help="write a table of the cases and their messages here")
    a = ap.parse_args()
    with open(os.path.join(HERE, "manifest.json")) as f:
        manifest = json.load(f)
    cli = os.path.abspath(a.cli)
    cases = [c for c in manifest["cases"] if not a.cases or c["file"] in a.cases]
    listed = {c["file"] for c in manifest["cases"]}
    unlisted = sorted(f for f in os.listdir(HERE) if f.endswith(".rib") and f not in listed)
    failed, rows = 0, []
    for case in cases:
        problems, code, err, seconds = run_case(cli, case)
        known = case.get("known_failure")
        if problems:
            verdict = "XFAIL" if known else "FAIL"
            failed += not known
        else:
            verdict = "XPASS" if known else "ok"
        first = err.strip().splitlines()[0] if err.strip() else ""
        print(f"{verdict:5} {case['file']:36} exit {code} {seconds:5.2f} s  {first[:160]}")
        for p in problems:
            print(f"        {p}")
        if known and problems:
            print(f"        known: {known}")
        rows.append((case, verdict, code, err.strip(), problems))
    if unlisted:
        print("FAIL  files missing from manifest.json: " + ", ".join(unlisted))
        failed += len(unlisted)
    if a.markdown:
        write_markdown(a.markdown, rows)
    print(f"{len(cases) - failed} of {len(cases)} cases handled as expected" if not failed else
          f"FAILED: {failed} case(s) not handled as expected")
    return 1 if failed else 0


def write_markdown(path, rows):
    def cell(text):
        return text.replace("|", "\\|").replace("\n", " / ")

    lines = ["| File | Checks | Expected | Exit | Message |", "|---|---|---|---|---|"]
    for case, verdict, code, err, problems in rows:
        message = err.replace("micropoly-render: ", "").replace(HERE + os.sep, "") if err else "(none)"
        if len(message) > 300:
            message = message[:300] + " …"
        expected = case["expect"] + ("" if verdict == "ok" else f" ({verdict})")
        lines.append(f"| {case['file']} | {cell(case['checks'])} | {expected} | {code} | `{cell(message)}` |")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    sys.exit(main())
