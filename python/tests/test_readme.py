"""The README's first screen: the two commands first, the first `localize` within 40 lines, at most 900 words, and
every relative link points at a file of the repository."""
import re

from conftest import REPO


def test_readme_first_screen():
    text = (REPO / "README.md").read_text()
    lines = text.splitlines()
    assert lines[3].startswith("./scripts/demo.sh") and lines[4].startswith("./scripts/test.sh")
    first = next(i for i, line in enumerate(lines) if re.search(r"\$B localize ", line))
    assert first < 40, first
    assert len(text.split()) <= 900
    assert (REPO / "docs" / "img" / "localize-0425-traj2.png").stat().st_size > 10_000


def test_relative_links_of_the_readme_and_the_guide_exist():
    for doc in (REPO / "README.md", REPO / "docs" / "crazyflie.md", REPO / "docs" / "usage.md",
                REPO / "docs" / "results.md"):
        for target in re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", doc.read_text()):
            if "://" in target:
                continue
            assert (doc.parent / target).exists(), f"{doc.name}: broken link {target}"
