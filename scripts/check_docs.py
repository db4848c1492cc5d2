#!/usr/bin/env python3
"""Checks the project's Markdown: links, images, the CLI's flags, the library's names.

  check_docs.py [--cli PATH_TO_FOGCL] [--installed PREFIX] [--root DIR]

1. Every relative link and image in README.md, docs/*.md and bench/results/README.md resolves: the
   file or folder exists, and a #fragment names a heading of the target Markdown file (GitHub's
   anchors: lower case, punctuation dropped, spaces to hyphens, -N for repeats).
2. With --cli: every flag that `fogcl apply --help`, `fogcl demo --help` and `fogcl report --help`
   print appears in docs/cli.md (as `--flag` in backquotes, or in the synopsis), and the first line
   of `fogcl --help` names both passes (the deferred fog and the fog volumes).

3. Every block of docs/*.md between `<!-- file: PATH -->` and `<!-- file-end -->` is a fenced
   block holding the repository's file PATH, word for word.
4. With --installed (a prefix fogcl was installed into): every header `fogcl/NAME.h` that
   docs/library.md names is installed; every name it writes `fogcl::Name[::member]` (anywhere), or
   in inline code as `Name::member`, `Name` (CamelCase), `snake_name` or `name(...)`, is declared
   in an installed header (comments aside), and every such function is linked: defined in an
   installed library (nm) or in a header.

Prints each problem on one line and exits 1 if there is any. Python 3 standard library only
(and nm, for --installed).
"""
import argparse
import re
import shutil
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


FILE_BLOCK = re.compile(r"<!-- file: (\S+) -->\n```\w*\n(.*?)```\n<!-- file-end -->", re.S)


def check_file_blocks(root, docs):
    """Blocks that show a whole file of the repository are that file."""
    problems, count = [], 0
    for doc in docs:
        for path, body in FILE_BLOCK.findall(doc.read_text()):
            count += 1
            target = root / path
            if not target.is_file():
                problems.append(f"{doc.relative_to(root)}: the block of {path}: no such file")
            elif target.read_text() != body:
                problems.append(f"{doc.relative_to(root)}: the block of {path} differs from the file")
    return problems, count


# Names in docs/library.md that are not C++ of fogcl's: CMake targets, other APIs, words.
NOT_FOGCL = {"fogcl", "io", "add_subdirectory", "find_package", "target_link_libraries", "InstallAndBuildExamples"}
# Names of the APIs fogcl meets (OpenCL's C types and extensions, Vulkan), not its own.
OTHER_APIS = ("std::", "cl::", "glm::", "Imath::", "OpenCL::", "CL_", "Unity", "cl_", "Vk", "vk", "VK_")


def installed_api(prefix):
    """(header file names, the headers' code without comments, nm's defined symbols)."""
    include = prefix / "include" / "fogcl"
    headers = {p.name: re.sub(r"//[^\n]*|/\*.*?\*/", "", p.read_text(), flags=re.S)
               for p in sorted(include.glob("*.h"))}
    libs = sorted(p for p in prefix.glob("lib*/**/libfogcl*") if p.suffix in (".so", ".a") and p.is_file())
    if not shutil.which("nm"):
        raise RuntimeError("nm is not installed (binutils)")
    symbols = ""
    for lib in libs:
        args = ["nm", "-C", "--defined-only"] + (["-D"] if lib.suffix == ".so" else []) + [str(lib)]
        symbols += subprocess.run(args, capture_output=True, text=True, check=True).stdout
    return headers, symbols, libs


def library_names(text):
    """(headers, names) docs/library.md refers to; a name is a tuple of its ::-parts."""
    header_refs = set(re.findall(r"\bfogcl/(\w+\.h)\b", text))
    names = set()
    for m in re.finditer(r"\bfogcl::(\w+(?:::\w+)*)", text):
        names.add(tuple(m.group(1).split("::")))
    prose = re.sub(r"^\s*```.*?^\s*```", "", text, flags=re.S | re.M)  # inline code only
    for span in re.findall(r"`([^`]+)`", prose):
        span = " ".join(span.split())
        if span.startswith(OTHER_APIS):
            continue
        m = re.fullmatch(r"([A-Z][a-z]\w*(?:::\w+)*)(?:\(\))?", span) or \
            re.fullmatch(r"(k[A-Z]\w*|[a-z]\w*_\w*)", span) or re.match(r"([a-z]\w*)\(", span)
        if m and not re.match(r"cl[A-Z]", m.group(1)):
            names.add(tuple(m.group(1).split("::")))
    return header_refs, {n for n in names if n[0] not in NOT_FOGCL}


def check_library_names(root, prefix):
    text = (root / "docs" / "library.md").read_text()
    headers, symbols, libs = installed_api(prefix)
    code = "\n".join(headers.values())
    header_refs, names = library_names(text)
    problems = [f"docs/library.md names fogcl/{h}, which is not installed"
                for h in sorted(header_refs - headers.keys())]
    functions = 0
    for name in sorted(names):
        shown = "::".join(name)
        missing = [part for part in name if not re.search(rf"\b{part}\b", code)]
        if missing:
            problems.append(f"docs/library.md names {shown}, but no installed header declares {missing[0]}")
            continue
        last = name[-1]
        if last[0].isupper() or not re.search(rf"\b{last}\s*\(", code):
            continue  # a type, constant, enumerator or field
        functions += 1
        inline = re.search(rf"\b{last}\s*\([^;{{}}]*\)[^;{{}}()]*\{{", code)
        if not inline and not re.search(rf"::{last}(\[abi:\w+\])?[(<]", symbols):
            problems.append(f"docs/library.md names {shown}, declared in an installed header but defined in no "
                            f"installed library ({', '.join(p.name for p in libs)})")
    summary = (f"docs/library.md's {len(header_refs)} headers and {len(names)} names are installed "
               f"({functions} functions linked)")
    return problems, summary


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", help="the fogcl executable; without it the flags are not checked")
    ap.add_argument("--installed", type=Path, help="an install prefix to check docs/library.md's names against")
    ap.add_argument("--root", default=Path(__file__).resolve().parent.parent, type=Path, help="repository root")
    args = ap.parse_args()
    root = args.root
    docs = [root / "README.md"] + sorted((root / "docs").glob("*.md")) + [root / "bench" / "results" / "README.md"]
    docs = [d for d in docs if d.exists()]
    problems = check_links(root, docs)
    summary = f"{len(docs)} documents' links and images resolve"
    block_problems, blocks = check_file_blocks(root, docs)
    problems += block_problems
    summary += f"; {blocks} whole-file blocks match their files"
    if args.installed:
        try:
            name_problems, name_summary = check_library_names(root, args.installed)
        except (OSError, RuntimeError, subprocess.CalledProcessError) as e:
            name_problems, name_summary = [f"reading the install at {args.installed}: {e}"], ""
        problems += name_problems
        summary += f"; {name_summary}"
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
