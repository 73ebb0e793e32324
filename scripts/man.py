#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The man pages of the tools, docs/man/TOOL.1, made from each tool's --help
(written once, in the tool) and a few lines of this file (a summary and the
pages to see also):

  man.py --write NAME=COMMAND...   rewrite docs/man/NAME.1 (`ninja -C build update-man`)
  man.py --check NAME=COMMAND...   exit 1 when a page is stale, groff warns on
                                   it, or an option --help lists is not in it
                                   (the test man-pages)

COMMAND is the tool's command line (shlex-split); it is run with --help and
COLUMNS=80. The --help layouts read: "usage:" lines, headings at column 0
ending in ":", options indented at most 6 spaces ("  -d, --dict NAME   text")
with deeper-indented continuation lines, paragraphs, and indented examples."""
import os
import re
import shlex
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MAN_DIR = os.path.join(ROOT, "docs", "man")

SUMMARY = {
    "frappe-detect": "find square fiducial markers (ArUco, AprilTag) in images, and their poses",
    "frappe-render": "draw markers, boards and test scenes of square fiducial markers",
    "frappe-receive": "read a robot's marker stream (frappejson over UDP or TCP) on a host",
    "frappe-watch": "serve a page showing a camera's annotated video and markers to a browser",
}
SEE_ALSO = {
    "frappe-detect": "frappe-render(1), gst-inspect-1.0(1) frappedetect",
    "frappe-render": "frappe-detect(1)",
    "frappe-receive": "frappe-watch(1), gst-inspect-1.0(1) frappejson",
    "frappe-watch": "frappe-receive(1), gst-inspect-1.0(1) frappedetect",
}
DOCS = {
    "frappe-detect": "docs/settings.md (every detector setting), docs/install.md",
    "frappe-render": "docs/quality.md",
    "frappe-receive": "docs/host.md (the Python module frappe.stream)",
    "frappe-watch": "docs/host.md, examples/stream-mjpeg.sh",
}

OPTION = re.compile(r"^( {1,6})(-\S.*?)(?: {2,}(\S.*))?$")


def esc(text):
    """Text for roff: backslashes, dashes as minus signs, no control line."""
    text = text.replace("\\", "\\e").replace("-", "\\-")
    return "\\&" + text if text.startswith((".", "'")) else text


def roff(name, help_text):
    lines = help_text.rstrip("\n").split("\n")
    out = [f'.TH {name.upper()} 1 "" "Frappe" "User Commands"', ".SH NAME", f"{name} \\- {esc(SUMMARY[name])}",
           ".SH SYNOPSIS", ".nf"]
    i = 0
    while i < len(lines) and (lines[i].startswith("usage:") or (i and lines[i].startswith(" ") and lines[i].strip())):
        out.append(esc(re.sub(r"^usage: ", "", lines[i]).strip() if lines[i].startswith("usage:")
                       else lines[i].strip()))
        i += 1
    out += [".fi", ".SH DESCRIPTION"]
    mode = None  # "text", "option", "verbatim"
    indent = 0
    rest = lines[i:]
    for k, line in enumerate(rest):
        following = next((l for l in rest[k + 1:] if l.strip()), "")
        if not line.strip():
            if mode == "verbatim":
                out.append(".fi")
            mode = None
            continue
        m = OPTION.match(line)
        if mode == "verbatim" and line.startswith(" "):
            out.append(esc(line))
        elif m and not (mode == "option" and len(m.group(1)) > indent):
            if mode == "verbatim":
                out.append(".fi")
            out += [".TP", f"\\fB{esc(m.group(2).strip())}\\fR"]
            if m.group(3):
                out.append(esc(m.group(3)))
            mode, indent = "option", len(m.group(1))
        elif mode == "option" and line.startswith(" " * (indent + 4)):
            out.append(esc(line.strip()))
        elif not line.startswith(" ") and line.rstrip().endswith(":") and OPTION.match(following):
            if mode == "verbatim":
                out.append(".fi")
            out.append(f".SS {esc(line.rstrip()[:-1])}")
            mode = None
        elif line.startswith(" "):
            if mode != "verbatim":
                out += [".PP", ".nf"] if mode != "text" else [".nf"]
                mode = "verbatim"
            out.append(esc(line))
        else:
            if mode == "verbatim":
                out.append(".fi")
            if mode != "text":
                out.append(".PP")
            out.append(esc(line.strip()))
            mode = "text"
    if mode == "verbatim":
        out.append(".fi")
    out += [".SH SEE ALSO", esc(SEE_ALSO[name]) + ";", f"in Frappe's documentation: {esc(DOCS[name])}."]
    return "\n".join(out) + "\n"


def tool_help(command):
    env = dict(os.environ, COLUMNS="80")
    p = subprocess.run(shlex.split(command) + ["--help"], capture_output=True, text=True, env=env, timeout=60)
    if p.returncode != 0:
        raise SystemExit(f"man.py: {command} --help: exit {p.returncode}\n{p.stderr}")
    return p.stdout or p.stderr


def render(path):
    """The page as text (groff, ASCII, no overstrike) and groff's warnings."""
    p = subprocess.run(["groff", "-man", "-Tascii", "-ww", "-P-cbou", path], capture_output=True, text=True)
    return p.stdout, p.stderr


def main():
    if len(sys.argv) < 3 or sys.argv[1] not in ("--write", "--check"):
        print(__doc__)
        return 2
    write = sys.argv[1] == "--write"
    failures = []
    for spec in sys.argv[2:]:
        name, _, command = spec.partition("=")
        help_text = tool_help(command)
        page = roff(name, help_text)
        path = os.path.join(MAN_DIR, name + ".1")
        if write:
            os.makedirs(MAN_DIR, exist_ok=True)
            with open(path, "w") as f:
                f.write(page)
            print(f"wrote {os.path.relpath(path, ROOT)}")
            continue
        old = open(path).read() if os.path.exists(path) else ""
        if old != page:
            failures.append(f"{os.path.relpath(path, ROOT)} is stale: `ninja -C build update-man` rewrites it")
            continue
        if not shutil.which("groff"):
            print(f"{name}: up to date (groff not installed: not rendered)")
            continue
        text, warnings = render(path)
        if warnings:
            failures.append(f"{name}.1: groff warns: {warnings}")
        options = sorted(set(re.findall(r"(?<![\w-])(--?[A-Za-z][\w-]*)", help_text)))
        missing = [o for o in options if not re.search(r"(?<![\w-])" + re.escape(o) + r"(?![\w-])", text)]
        if missing:
            failures.append(f"{name}.1 lacks options of its --help: {', '.join(missing)}")
        else:
            print(f"{name}.1: up to date, renders without warnings, has all {len(options)} options of --help")
    for f in failures:
        print(f"FAIL: {f}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
