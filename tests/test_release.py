"""Release hygiene: licence in the installed metadata, one version, a citation file that parses
against the Citation File Format 1.2 rules (https://citation-file-format.github.io/1.2.0/),
and ``exucable --version``."""

from __future__ import annotations

import re
import subprocess
import sys
from importlib import metadata
from pathlib import Path

import pytest

import exucable

ROOT = Path(__file__).resolve().parents[1]

# CFF 1.2.0 schema: the keys every file must have, and the patterns of the ones checked below
CFF_REQUIRED = ("cff-version", "message", "title", "authors")
CFF_REFERENCE_REQUIRED = ("type", "title", "authors")
DOI = re.compile(r"^10\.\d{4,9}(\.\d+)?/[A-Za-z0-9:/_;\-\.\(\)\[\]\\]+$")
DATE = re.compile(r"^\d{4}-\d{2}-\d{2}$")


def test_installed_metadata_carries_the_licence_and_the_one_version():
    meta = metadata.metadata("exucable")
    assert meta["License-Expression"] == "BSD-3-Clause"
    assert meta["Version"] == exucable.__version__
    assert (ROOT / "LICENSE").read_text().startswith("BSD 3-Clause License")


def _authors_valid(authors) -> bool:
    return (isinstance(authors, list) and len(authors) > 0
            and all(isinstance(a, dict) and ("family-names" in a or "name" in a) for a in authors))


def test_citation_file_follows_cff_1_2():
    yaml = pytest.importorskip("yaml")
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    for key in CFF_REQUIRED:
        assert key in cff, f"CITATION.cff lacks the required key {key!r}"
    assert cff["cff-version"] == "1.2.0"
    assert _authors_valid(cff["authors"])
    assert str(cff["version"]) == exucable.__version__
    assert DATE.match(str(cff["date-released"]))
    assert cff["license"] == "BSD-3-Clause"
    dois = []
    for ref in cff["references"]:
        for key in CFF_REFERENCE_REQUIRED:
            assert key in ref, f"a reference in CITATION.cff lacks {key!r}"
        assert _authors_valid(ref["authors"])
        assert DOI.match(ref["doi"])
        dois.append(ref["doi"])
    # the paper exucable implements and the engine it runs on
    assert "10.1007/s11044-013-9364-9" in dois and "10.1007/s11044-023-09937-1" in dois


def test_readme_says_how_to_cite_and_the_licence():
    readme = (ROOT / "README.md").read_text()
    assert "## How to cite" in readme
    assert "BSD-3-Clause" in readme
    for doi in ("10.1007/s11044-013-9364-9", "10.1007/s11044-023-09937-1"):
        assert doi in readme


def test_changelog_has_the_current_version():
    changelog = (ROOT / "CHANGELOG.md").read_text()
    assert f"## [{exucable.__version__}]" in changelog


def test_version_option_prints_exucable_and_exudyn_versions():
    import exudyn
    out = subprocess.run([sys.executable, "-m", "exucable", "--version"], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0
    assert f"exucable {exucable.__version__}" in out.stdout
    assert f"Exudyn {exudyn.__version__}" in out.stdout
