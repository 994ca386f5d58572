"""Citations of the physics notes point at sections that exist; nothing cites outside the repo."""

import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CITE = re.compile(r"docs/physics\.md,?\s+§\s*(\d+)")
HEADING = re.compile(r"^## §(\d+) ", re.MULTILINE)


def _tracked_text_files():
    out = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True)
    if out.returncode != 0:   # not a git checkout (an sdist): walk the tree instead
        names = [str(p.relative_to(ROOT)) for p in ROOT.rglob("*") if p.is_file()]
    else:
        names = out.stdout.splitlines()
    for name in names:
        if name.endswith((".py", ".md", ".ipynb", ".toml", ".txt", ".rst")):
            yield ROOT / name


def test_every_cited_section_exists():
    sections = {int(n) for n in HEADING.findall((ROOT / "docs/physics.md").read_text())}
    assert sections >= set(range(1, 10))
    missing = []
    for path in _tracked_text_files():
        text = path.read_text(encoding="utf-8", errors="replace")
        # a citation may break across a line: "docs/physics.md\n    §7"
        for m in CITE.finditer(re.sub(r"\s+", " ", text)):
            if int(m.group(1)) not in sections:
                missing.append(f"{path.relative_to(ROOT)}: §{m.group(1)}")
    assert not missing, missing


def test_no_file_outside_the_repository_is_cited():
    bad = re.compile(r"PHYSICS\.md|LITERATURE\.md|STYLE\.md|shared/paper|/work/")
    found = [f"{p.relative_to(ROOT)}: {m.group(0)}" for p in _tracked_text_files()
             if p.name != "test_docs_citations.py"
             for m in bad.finditer(p.read_text(encoding="utf-8", errors="replace"))]
    assert not found, found
