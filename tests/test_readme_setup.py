"""The README's set-up block, as .ci/run extracts and runs it (.ci/readme_setup.py), and
what the README shows (links, figures, the tour's scenario) exists and is valid."""

import importlib.util
import re
import subprocess
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
_spec = importlib.util.spec_from_file_location("readme_setup", ROOT / ".ci" / "readme_setup.py")
readme_setup = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(readme_setup)


def test_readme_block_is_found_with_both_install_commands():
    commands = readme_setup.extract((ROOT / "README.md").read_text(encoding="utf-8"))
    assert commands[0].startswith("python3.11 -m venv .venv")
    assert any(c.startswith("pip install . ") for c in commands)
    assert any(c.startswith('pip install -e ".[test]"') for c in commands)


@pytest.mark.parametrize("text, message", [
    ("# hertzchain\n\n## Install\n```bash\nls\n```\n", "no heading starting with 'Set-up'"),
    ("## Set-up\ntext\n## Next\n```bash\nls\n```\n", "no fenced code block before"),
    ("## Set-up\n```bash\n# only a comment\n```\n", "is empty"),
    ("## Set-up\n```bash\nls\n", "never closed"),
    ("## Set-up\n```python\nprint(1)\n```\n", "expected bash"),
])
def test_missing_or_bad_block_fails_loudly(text, message):
    with pytest.raises(ValueError, match=message):
        readme_setup.extract(text)


def test_script_stops_at_the_first_failing_line_even_left_of_and(tmp_path):
    # bash's set -e would go on after `false && echo`: the generated script must not
    text = "## Set-up\n```bash\necho one\nfalse && echo two\necho three \\\n  four\n```\n"
    script = readme_setup.script(readme_setup.extract(text))
    out = subprocess.run(["bash", "-c", script], capture_output=True, text=True)
    assert out.returncode == 1
    assert "one" in out.stdout and "three" not in out.stdout
    assert "README set-up line 2 failed" in out.stderr
    ok = readme_setup.script(readme_setup.extract(text.replace("false && ", "")))
    out = subprocess.run(["bash", "-c", ok], capture_output=True, text=True)
    assert out.returncode == 0 and "three four" in out.stdout


# -- the README as a front page: what it shows must exist and parse -----------------------
README = (ROOT / "README.md").read_text(encoding="utf-8")


def test_install_page_includes_the_set_up_block_between_its_markers():
    # docs/guide/install.md includes the README from the start marker to the end marker
    install = (ROOT / "docs" / "guide" / "install.md").read_text(encoding="utf-8")
    start = "<!-- docs: set-up start (docs/guide/install.md includes from here) -->"
    end = "<!-- docs: set-up end -->"
    assert f'start-after: "{start}"' in install and f'end-before: "{end}"' in install
    assert README.count(start) == 1 and README.count(end) == 1
    included = README[README.index(start):README.index(end)]
    assert "\n".join(readme_setup.extract(README)) in included   # the block CI runs


def test_local_links_and_images_exist():
    links = re.findall(r"\]\(([^)\s#]+)\)", README)
    local = [link for link in links if "://" not in link]
    assert "docs/figures/compare_profiles.png" in local
    for link in local:
        assert (ROOT / link).exists(), f"README links {link}, which does not exist"
    for image in re.findall(r"!\[[^\]]*\]\(([^)\s]+)\)", README):
        assert (ROOT / image).stat().st_size < 150_000, f"{image} is over 150 kB"


def test_tour_scenario_is_valid():
    from hertzchain.scenario import parse_scenario

    tour = README[README.index("## A five-minute tour"):]
    toml = re.search(r"```toml\n(.*?)```", tour, re.S).group(1)
    sc = parse_scenario(tomllib.loads(toml))
    assert sc.name == "my-chain" and sc.chain.n == 500 and sc.models.continuum
