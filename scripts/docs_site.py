#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Builds the documentation as a browsable HTML site with MkDocs (Debian's `mkdocs`), warnings as
errors:

    python3 scripts/docs_site.py SITE_DIR      # then open SITE_DIR/index.html

The site holds the front page (README.md), the user guide (docs/guide/, its reference pages
generated from the code by scripts/reference_pages.py), the C++ reference (Doxygen, from the public
headers' comments, warnings as errors), the theory (docs/theory.md, docs/theory/),
the JSON schemas' page and every file those pages link to (the CHANGELOG, the LinuxCNC module's
README, configurations, examples, headers), found by following the links from the front page and the
guide. A link to a file that does not exist, or a page MkDocs cannot build, fails the build (exit 1),
so the tests (Docs.SiteBuildsWithoutWarnings) keep every link of the guide working.
"""
from __future__ import annotations

import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LINK = re.compile(r"\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")


def local_target(page: Path, link: str) -> Path | None:
    if re.match(r"^[a-z][a-z0-9+.-]*:", link) or link.startswith("#"):
        return None  # a URL or an anchor on the page
    target = (page.parent / link.split("#", 1)[0]).resolve()
    return target


def collect(start: list[Path]) -> tuple[list[Path], list[str]]:
    """Every file reachable by links from `start`, and the links that point outside the repository."""
    seen: dict[Path, None] = {}
    outside: list[str] = []
    todo = list(start)
    while todo:
        page = todo.pop()
        if page in seen:
            continue
        seen[page] = None
        if page.suffix != ".md" or not page.is_file():
            continue
        text = re.sub(r"```.*?```", "", page.read_text(encoding="utf-8"), flags=re.S)  # not links in code
        for link in LINK.findall(text):
            target = local_target(page, link)
            if target is None:
                continue
            if ROOT not in target.parents:
                outside.append(f"{page.relative_to(ROOT)}: {link}")
                continue
            if target not in seen:
                todo.append(target)
    return sorted(seen), outside


def doxygen(stage: Path) -> str | None:
    """The C++ reference from the public headers' comments (Doxygen, warnings as errors) into
    stage/docs/cpp-reference/; its messages when it fails, else None."""
    exe = shutil.which("doxygen")
    if exe is None:
        return "doxygen not found (apt-get install doxygen; scripts/setup.sh installs it)"
    out = stage / "docs" / "cpp-reference"
    config = stage.parent / "Doxyfile"
    config.write_text(
        "PROJECT_NAME = hexatwist\n"
        "PROJECT_BRIEF = \"The C++ library: include/hexatwist/, one header per concept\"\n"
        f"INPUT = {ROOT / 'include' / 'hexatwist'}\n"
        "RECURSIVE = YES\nFILE_PATTERNS = *.hpp *.h\n"
        f"STRIP_FROM_PATH = {ROOT / 'include'}\nSTRIP_FROM_INC_PATH = {ROOT / 'include'}\nFULL_PATH_NAMES = YES\n"
        f"OUTPUT_DIRECTORY = {out.parent}\nHTML_OUTPUT = {out.name}\nGENERATE_HTML = YES\nGENERATE_LATEX = NO\n"
        "EXTRACT_ALL = YES\nJAVADOC_AUTOBRIEF = YES\nMARKDOWN_SUPPORT = YES\nHAVE_DOT = NO\nSEARCHENGINE = NO\n"
        "QUIET = YES\nWARN_IF_UNDOCUMENTED = NO\nWARN_IF_DOC_ERROR = YES\nWARN_AS_ERROR = FAIL_ON_WARNINGS\n",
        encoding="utf-8")
    result = subprocess.run([exe, str(config)], capture_output=True, text=True, timeout=600)
    messages = (result.stdout + result.stderr).strip()
    if result.returncode != 0 or "warning" in messages or not (out / "index.html").is_file():
        return messages or f"doxygen failed (exit {result.returncode})"
    return None


def nav_of(files: list[Path]) -> str:
    """The site's menu: the front page, the guide in its index's reading order, the theory, the rest."""
    rel = [f.relative_to(ROOT).as_posix() for f in files if f.suffix == ".md" and f.is_file()]
    index = (ROOT / "docs/guide/index.md").read_text(encoding="utf-8")
    guide = ["docs/guide/index.md"]
    for link in LINK.findall(index):
        p = (ROOT / "docs/guide" / link.split("#", 1)[0]).resolve().relative_to(ROOT).as_posix()
        if p.startswith("docs/guide/") and p in rel and p not in guide:
            guide.append(p)
    guide += sorted(p for p in rel if p.startswith("docs/guide/") and p not in guide)
    theory = [p for p in ["docs/theory.md", "docs/notation.md"] if p in rel]
    theory += sorted(p for p in rel if p.startswith("docs/theory/"))
    rest = sorted(p for p in rel if p not in guide and p not in theory and p != "README.md")

    def entries(paths: list[str]) -> str:
        return "".join(f"      - '{p}'\n" for p in paths)

    return ("nav:\n  - Home: 'README.md'\n  - Guide:\n" + entries(guide) + "  - Theory:\n" + entries(theory) +
            "  - More:\n" + entries(rest) + "  - C++ reference: 'docs/cpp-reference/index.html'\n")


def main() -> int:
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    site = Path(sys.argv[1]).resolve()
    # The site replaces an earlier site only: never a folder of anything else (the sources above all).
    earlier = site.is_dir() and any(site.iterdir())
    if earlier and not ((site / "sitemap.xml").is_file() and (site / "index.html").is_file()):
        print(f"docs_site: {site} holds files that are not a site this script built: name a new folder",
              file=sys.stderr)
        return 2
    if site.exists() and not site.is_dir():
        print(f"docs_site: {site} is a file: name a folder", file=sys.stderr)
        return 2
    starts = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    files, outside = collect(starts)
    if outside:
        for o in outside:
            print(f"docs_site: a link leaves the repository: {o}", file=sys.stderr)
        return 1
    mkdocs = shutil.which("mkdocs")
    if mkdocs is None:
        print("docs_site: mkdocs not found (apt-get install mkdocs; scripts/setup.sh installs it)", file=sys.stderr)
        return 1
    with tempfile.TemporaryDirectory(prefix="hexatwist-site-") as tmp:
        stage = Path(tmp) / "src"
        for f in files:
            if not f.exists():
                continue  # MkDocs names the page and the link (a warning, so the build fails)
            dest = stage / f.relative_to(ROOT)
            dest.parent.mkdir(parents=True, exist_ok=True)
            if f.is_dir():
                shutil.copytree(f, dest, dirs_exist_ok=True)
            else:
                shutil.copy2(f, dest)
        problem = doxygen(stage)
        if problem is not None:
            print(problem.replace(str(ROOT) + "/", ""), file=sys.stderr)
            print("docs_site: the C++ reference (Doxygen) failed: the site was not built", file=sys.stderr)
            return 1
        config = Path(tmp) / "mkdocs.yml"
        config.write_text(
            "site_name: hexatwist\n"
            "site_description: Twist-aware kinematics, simulation and calibration of lead-screw Stewart platforms\n"
            "docs_dir: src\n"
            "site_dir: site\n"
            "strict: true\n"
            "use_directory_urls: false\n"  # opens from the file system, without a web server
            "theme:\n  name: mkdocs\n"
            "markdown_extensions:\n  - tables\n  - fenced_code\n  - toc:\n      permalink: true\n" + nav_of(files),
            encoding="utf-8")
        result = subprocess.run([mkdocs, "build", "--clean", "-f", str(config)], capture_output=True, text=True,
                                timeout=600)
        # MkDocs' own lines but its progress (INFO): the warnings and errors, each naming the page.
        messages = [re.sub(r"\x1b\[[0-9;]*m", "", line).replace(str(stage) + "/", "")
                    for line in (result.stdout + result.stderr).splitlines() if not line.startswith("INFO")]
        if result.returncode != 0:
            print("\n".join(m for m in messages if m.strip()), file=sys.stderr)
            print(f"docs_site: mkdocs failed (exit {result.returncode}): the site was not built", file=sys.stderr)
            return 1
        # Built whole: only now does it replace the earlier one.
        if site.exists():
            shutil.rmtree(site)
        site.parent.mkdir(parents=True, exist_ok=True)
        shutil.move(str(Path(tmp) / "site"), str(site))
    pages = sum(1 for _ in site.rglob("*.html"))
    print(f"docs_site: {pages} HTML pages in {site} (open {site / 'index.html'})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
