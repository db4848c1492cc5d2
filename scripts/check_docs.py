#!/usr/bin/env python3
"""Checks the project's Markdown: links, images and the CLI's flags.

  check_docs.py [--cli PATH_TO_FOGCL] [--root DIR]

1. Every relative link and image in README.md, docs/*.md and bench/results/README.md resolves: the
   file or folder exists, and a #fragment names a heading of the target Markdown file (GitHub's
   anchors: lower case, punctuation dropped, spaces to hyphens, -N for repeats).
2. With --cli: every flag that `fogcl apply --help`, `fogcl demo --help` and `fogcl report --help`
   print appears in docs/cli.md (as `--flag` in backquotes, or in the synopsis), and the first line
   of `fogcl --help` names both passes (the deferred fog and the fog volumes).

Prints each problem on one line and exits 1 if there is any. Python 3 standard library only.
"""
import argparse
import re
import subprocess
import sys
from pathlib import Path

LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
HTML_SRC = re.compile(r"<(?:img|a)\s[^>]*(?:src|href)=\"([^\"]+)\"", re.I)
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")
FENCE = re.compile(r"^\s*(```|~~~)")
FLAG = re.compile(r"(?<![\w-])(--[a-z][a-z0-9-]*)")
SUBCOMMANDS = ("apply", "demo", "report")


def strip_code(text):
    """The text without fenced blocks and inline code, where links are not links."""
    out, fenced = [], False
    for line in text.splitlines():
        if FENCE.match(line):
            fenced = not fenced
            out.append("")
            continue
        out.append("" if fenced else re.sub(r"`[^`]*`", "``", line))
    return "\n".join(out)


def anchors(path):
    """GitHub's heading anchors of a Markdown file."""
    seen, result, fenced = {}, set(), False
    for line in path.read_text().splitlines():
        if FENCE.match(line):
            fenced = not fenced
            continue
        m = None if fenced else HEADING.match(line)
        if not m:
            continue
        title = re.sub(r"`([^`]*)`", r"\1", m.group(2))
        title = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", title)  # a link's text
        slug = re.sub(r"[^\w\- ]", "", title.strip().lower()).replace(" ", "-")
        n = seen.get(slug, 0)
        seen[slug] = n + 1
        result.add(slug if n == 0 else f"{slug}-{n}")
    return result


def check_links(root, docs):
    problems, cache = [], {}
    for doc in docs:
        text = strip_code(doc.read_text())
        targets = LINK.findall(text) + HTML_SRC.findall(text)
        for target in targets:
            if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):  # http:, https:, mailto:
                continue
            path_part, _, fragment = target.partition("#")
            dest = (doc.parent / path_part).resolve() if path_part else doc.resolve()
            where = f"{doc.relative_to(root)}: ({target})"
            try:
                dest.relative_to(root.resolve())
            except ValueError:
                problems.append(f"{where} points outside the repository")
                continue
            if not dest.exists():
                problems.append(f"{where}: {path_part} does not exist")
                continue
            if fragment:
                if dest.suffix != ".md" or not dest.is_file():
                    problems.append(f"{where}: a #fragment on a file that is not Markdown")
                    continue
                if dest not in cache:
                    cache[dest] = anchors(dest)
                if fragment not in cache[dest]:
                    problems.append(f"{where}: {dest.relative_to(root.resolve())} has no heading "
                                    f"with the anchor #{fragment}")
    return problems


def cli_flags(cli, sub):
    run = subprocess.run([cli, sub, "--help"], capture_output=True, text=True, timeout=60)
    if run.returncode != 0:
        raise RuntimeError(f"{cli} {sub} --help exited {run.returncode}: {run.stderr.strip()}")
    flags = set()
    for line in run.stdout.splitlines():
        m = re.match(r"^\s+(?:-\w,)?(--[a-z][a-z0-9-]*)", line)
        if m:
            flags.add(m.group(1))
    if not flags:
        raise RuntimeError(f"{cli} {sub} --help printed no flags")
    return flags


def check_flags(root, cli):
    page = root / "docs" / "cli.md"
    documented = set(FLAG.findall(page.read_text()))
    problems, count = [], 0
    try:
        run = subprocess.run([cli, "--help"], capture_output=True, text=True, timeout=60)
        first = (run.stdout.splitlines() or [""])[0]
        if "deferred fog" not in first or "volum" not in first:
            problems.append(f"the first line of `fogcl --help` does not name both passes (deferred fog, fog "
                            f"volumes): {first!r}")
    except (OSError, subprocess.TimeoutExpired) as e:
        problems.append(f"fogcl --help: {e}")
    for sub in SUBCOMMANDS:
        try:
            flags = cli_flags(cli, sub)
        except (OSError, RuntimeError, subprocess.TimeoutExpired) as e:
            problems.append(f"fogcl {sub} --help: {e}")
            continue
        count += len(flags)
        for flag in sorted(flags - documented):
            problems.append(f"docs/cli.md does not mention `{flag}`, which `fogcl {sub} --help` prints")
    return problems, count


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", help="the fogcl executable; without it the flags are not checked")
    ap.add_argument("--root", default=Path(__file__).resolve().parent.parent, type=Path, help="repository root")
    args = ap.parse_args()
    root = args.root
    docs = [root / "README.md"] + sorted((root / "docs").glob("*.md")) + [root / "bench" / "results" / "README.md"]
    docs = [d for d in docs if d.exists()]
    problems = check_links(root, docs)
    summary = f"{len(docs)} documents' links and images resolve"
    if args.cli:
        flag_problems, count = check_flags(root, args.cli)
        problems += flag_problems
        summary += f"; docs/cli.md names all {count} flags of fogcl {', '.join(SUBCOMMANDS)}"
    for p in problems:
        print(f"check_docs: {p}", file=sys.stderr)
    if problems:
        print(f"check_docs: {len(problems)} problem(s)", file=sys.stderr)
        return 1
    print(f"check_docs: {summary}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
