#!/usr/bin/env python3
"""Checks that the documentation reads as documentation and that what it shows works.

    python3 .ci/check_docs.py words      # no word about how the work is organised
    python3 .ci/check_docs.py links      # every relative link and anchor resolves
    python3 .ci/check_docs.py commands   # the listed README and user-guide commands run
    python3 .ci/check_docs.py selftest   # each check fails on a planted fault
    python3 .ci/check_docs.py            # words, links, commands

Run from anywhere; paths are taken from the repository root (this file's parent folder).
`commands` needs the release binary (`target/release/tdex`, or `TDEX_BIN`) and runs the
commands of `.ci/doc-commands.txt` in order, in one scratch folder holding a copy of
`cases/`, each with a time limit. Exit status 1 when any check fails, with one line per
finding naming the file, the line and what is wrong.
"""

import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import unicodedata
from pathlib import Path

# TDEX_CHECK_ROOT points the checks at another tree (the self-test's planted copies)
ROOT = Path(os.environ.get("TDEX_CHECK_ROOT", Path(__file__).resolve().parent.parent)).resolve()
COMMANDS_FILE = ROOT / ".ci" / "doc-commands.txt"
COMMAND_SOURCES = [ROOT / "README.md", ROOT / "docs" / "user-guide.md"]
COMMAND_TIMEOUT_S = 120

# Words that speak of how the work is organised rather than of the software. `owner` is
# also a technical word in the Rust code (the particle that holds a contact, the row that
# holds a column in the auction), so it is refused in prose only.
WORDS_EVERYWHERE = [
    (re.compile(r"\bsessions?\b", re.I), "a working session"),
    (re.compile(r"\b(issue|task|ticket)s?\s*#?\d+", re.I), "an issue number"),
    (re.compile(r"\bsub-?agents?\b", re.I), "an agent"),
    (re.compile(r"\bCEO\b"), "the CEO"),
    (re.compile(r"\bhelper's\b|\bthe helper\b", re.I), "a helper"),
    (re.compile(r"DEVELOPERS\.md"), "the developers' brief"),
]
WORDS_IN_PROSE = [
    (re.compile(r"\bowners?\b", re.I), "an owner"),
]
PROSE_SUFFIXES = {".md", ".toml", ".py", ".sh", ".txt"}
CODE_SUFFIXES = {".rs"}
WORD_SCOPES = ["README.md", "docs", "cases", "src", "recorder", "extrapolate", "tests", "fuzz"]
SKIP_DIRS = {"target", ".git", "node_modules", "__pycache__"}


def files_under(scopes, suffixes):
    for scope in scopes:
        path = ROOT / scope
        if path.is_file():
            if path.suffix in suffixes:
                yield path
            continue
        for dirpath, dirnames, filenames in os.walk(path):
            dirnames[:] = sorted(d for d in dirnames if d not in SKIP_DIRS)
            for name in sorted(filenames):
                p = Path(dirpath) / name
                if p.suffix in suffixes:
                    yield p


def rel(path):
    return path.relative_to(ROOT).as_posix()


def check_words():
    findings = []
    for path in files_under(WORD_SCOPES, PROSE_SUFFIXES | CODE_SUFFIXES):
        patterns = WORDS_EVERYWHERE + (WORDS_IN_PROSE if path.suffix in PROSE_SUFFIXES else [])
        text = path.read_text(encoding="utf-8", errors="replace")
        for lineno, line in enumerate(text.splitlines(), 1):
            for pattern, what in patterns:
                m = pattern.search(line)
                if m:
                    findings.append(
                        f"{rel(path)}:{lineno}: '{m.group(0)}' speaks of {what}, not of the "
                        f"software: {line.strip()[:120]}"
                    )
    return findings


# --- links -------------------------------------------------------------------------------

FENCE = re.compile(r"^\s*(```|~~~)")
INLINE_CODE = re.compile(r"`+[^`]*`+")
MD_LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
HTML_LINK = re.compile(r"""<(?:a|img)\b[^>]*?\b(?:href|src)\s*=\s*["']([^"']+)["']""", re.I)
HTML_ANCHOR = re.compile(r"""<[a-z]+\b[^>]*?\b(?:id|name)\s*=\s*["']([^"']+)["']""", re.I)
HEADING = re.compile(r"^ {0,3}(#{1,6})\s+(.*?)\s*#*\s*$")


def slug(heading):
    """GitHub's anchor for a heading: the rendered text, lower-cased, without punctuation,
    spaces as hyphens."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # links keep their text
    text = re.sub(r"<[^>]+>", "", text)  # inline HTML
    text = text.replace("`", "").replace("*", "")
    text = re.sub(r"(?<![A-Za-z0-9])_+|_+(?![A-Za-z0-9])", "", text)  # emphasis underscores
    kept = []
    for ch in text.lower():
        cat = unicodedata.category(ch)
        if ch in " -_" or cat[0] in "LNM" or cat == "Pc":
            kept.append(ch)
    return "".join(kept).replace(" ", "-")


def markdown_lines(text):
    """The lines outside fenced code blocks, with inline code removed."""
    fenced = False
    for lineno, line in enumerate(text.splitlines(), 1):
        if FENCE.match(line):
            fenced = not fenced
            continue
        if not fenced:
            yield lineno, INLINE_CODE.sub("", line)


_anchor_cache = {}


def anchors_of(path):
    if path not in _anchor_cache:
        anchors, seen, fenced = set(), {}, False
        for line in path.read_text(encoding="utf-8", errors="replace").splitlines():
            if FENCE.match(line):
                fenced = not fenced
                continue
            if fenced:
                continue
            m = HEADING.match(line)
            if m:
                base = slug(m.group(2))
                n = seen.get(base, 0)
                seen[base] = n + 1
                anchors.add(base if n == 0 else f"{base}-{n}")
            anchors.update(HTML_ANCHOR.findall(line))
        _anchor_cache[path] = anchors
    return _anchor_cache[path]


def check_links():
    findings = []
    for path in files_under(["README.md", "docs"], {".md"}):
        text = path.read_text(encoding="utf-8", errors="replace")
        for lineno, line in markdown_lines(text):
            for target in MD_LINK.findall(line) + HTML_LINK.findall(line):
                if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):
                    continue  # http:, https:, mailto: ... not checked offline
                file_part, _, anchor = target.partition("#")
                dest = path if not file_part else (path.parent / file_part).resolve()
                where = f"{rel(path)}:{lineno}: link '{target}'"
                if not dest.exists():
                    findings.append(f"{where}: no file {file_part} (from {rel(path.parent) or '.'}/)")
                    continue
                try:
                    dest.relative_to(ROOT)
                except ValueError:
                    findings.append(f"{where}: points outside the repository")
                    continue
                if anchor:
                    if dest.suffix != ".md":
                        findings.append(f"{where}: an anchor into a file that is not Markdown")
                    elif anchor not in anchors_of(dest):
                        findings.append(f"{where}: no heading with anchor #{anchor} in {rel(dest)}")
    return findings


# --- commands ----------------------------------------------------------------------------


def strip_comment(line):
    """A shell line without its trailing `# comment` (a # outside quotes, after a space)."""
    quote = None
    for i, ch in enumerate(line):
        if quote:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch == "#" and (i == 0 or line[i - 1].isspace()):
            return line[:i].strip()
    return line.strip()


def documented_commands():
    shown = set()
    for path in COMMAND_SOURCES:
        fenced = None
        for line in path.read_text(encoding="utf-8").splitlines():
            m = FENCE.match(line)
            if m:
                fenced = None if fenced is not None else line.strip()[3:].strip()
                continue
            if fenced in ("sh", "bash", "console", "shell"):
                shown.add(strip_comment(line.lstrip("$ ").rstrip()))
    return shown


def check_commands():
    binary = Path(os.environ.get("TDEX_BIN", ROOT / "target" / "release" / "tdex"))
    if not binary.is_file():
        return [f"no tdex binary at {binary}: build it first (cargo build --release)"]
    if not COMMANDS_FILE.is_file():
        return [f"no command list {rel(COMMANDS_FILE)}"]
    shown = documented_commands()
    commands, findings = [], []
    for lineno, line in enumerate(COMMANDS_FILE.read_text(encoding="utf-8").splitlines(), 1):
        command = strip_comment(line)
        if not command:
            continue
        if command not in shown:
            findings.append(
                f"{rel(COMMANDS_FILE)}:{lineno}: '{command}' is not shown in a sh block of "
                f"README.md or docs/user-guide.md (the list must follow the docs)"
            )
        commands.append((lineno, command))
    if findings:
        return findings
    scratch = Path(tempfile.mkdtemp(prefix="tdex-doc-commands-"))
    shutil.copytree(ROOT / "cases", scratch / "cases")
    env = dict(os.environ, PATH=f"{binary.parent}{os.pathsep}{os.environ.get('PATH', '')}")
    try:
        for lineno, command in commands:
            started = time.monotonic()
            try:
                run = subprocess.run(
                    ["bash", "-c", command], cwd=scratch, env=env, capture_output=True,
                    text=True, timeout=COMMAND_TIMEOUT_S,
                )
            except subprocess.TimeoutExpired:
                findings.append(
                    f"{rel(COMMANDS_FILE)}:{lineno}: '{command}' ran over {COMMAND_TIMEOUT_S} s"
                )
                break
            seconds = time.monotonic() - started
            if run.returncode != 0:
                tail = (run.stderr or run.stdout).strip().splitlines()[-3:]
                findings.append(
                    f"{rel(COMMANDS_FILE)}:{lineno}: '{command}' exited with {run.returncode}: "
                    + " | ".join(tail)
                )
                break
            print(f"ok {seconds:6.1f} s  {command}")
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return findings


# --- self-test ---------------------------------------------------------------------------

PLANTS = {
    # check: (file to change, text appended to it)
    "words": ("docs/method.md", "\nMeasured in the third session.\n"),
    "links": ("docs/method.md", "\nSee [the theory](theory.md#no-such-heading).\n"),
    "commands": (
        "docs/user-guide.md",
        "\n```sh\ntdex record cases/no_such_case.toml -o run.mcap\n```\n",
    ),
}


def check_selftest():
    """Each check must pass on a copy of the tree and fail once a fault is planted in it."""
    findings = []
    for name, (target, plant) in PLANTS.items():
        with tempfile.TemporaryDirectory(prefix="tdex-doc-selftest-") as tmp:
            copy = Path(tmp)
            shutil.copy2(ROOT / "README.md", copy / "README.md")
            for folder in ("docs", "cases"):
                shutil.copytree(ROOT / folder, copy / folder)
            (copy / ".ci").mkdir()
            (copy / ".ci" / "doc-commands.txt").write_text(
                "tdex record cases/no_such_case.toml -o run.mcap\n" if name == "commands" else ""
            )
            env = dict(os.environ, TDEX_CHECK_ROOT=str(copy))
            env.setdefault("TDEX_BIN", str(ROOT / "target" / "release" / "tdex"))
            script = [sys.executable, str(Path(__file__).resolve()), name]
            if name != "commands":
                clean = subprocess.run(script, env=env, capture_output=True, text=True)
                if clean.returncode != 0:
                    findings.append(f"selftest {name}: fails on the unchanged copy: {clean.stderr.strip()[:300]}")
                    continue
            with open(copy / target, "a", encoding="utf-8") as f:
                f.write(plant)
            planted = subprocess.run(script, env=env, capture_output=True, text=True)
            first = (planted.stderr.strip().splitlines() or ["(nothing)"])[0]
            if planted.returncode != 1:
                findings.append(f"selftest {name}: passed with a planted fault in {target}")
            else:
                print(f"selftest {name}: a planted fault in {target} fails it: {first}")
    return findings


CHECKS = {"words": check_words, "links": check_links, "commands": check_commands}
EXTRA = {"selftest": check_selftest}


def main(argv):
    sys.stdout.reconfigure(line_buffering=True)
    names = argv or list(CHECKS)
    every = {**CHECKS, **EXTRA}
    unknown = [n for n in names if n not in every]
    if unknown:
        print(f"unknown check {unknown[0]!r}: the checks are {', '.join(every)}", file=sys.stderr)
        return 2
    failed = False
    for name in names:
        findings = every[name]()
        for f in findings:
            print(f, file=sys.stderr)
        print(f"{name}: {'FAILED, ' + str(len(findings)) + ' finding(s)' if findings else 'ok'}")
        failed |= bool(findings)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
