"""Layering rules that keep the project livable (docs/architecture.md, "Rules").

* the metric module is pure: importing it pulls in no simulator, no torch and
  no plotting library, so real-robot users can score logs anywhere;
* importing the CLI imports no simulator (subcommands load lazily);
* the CLI imports no strategy (scoring of stored trials is the runner's);
* only ``benchharness/backends`` imports pybullet or sapien.
"""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "benchharness"
HEAVY = ("pybullet", "sapien", "torch", "matplotlib")


@pytest.mark.parametrize(
    "module", ["benchharness.metrics", "benchharness.cli.main", "benchharness.cube"]
)
def test_import_is_light(module):
    code = (
        f"import sys, {module}\n"
        f"heavy = sorted({{m.split('.')[0] for m in sys.modules}} & set({HEAVY!r}))\n"
        "print(','.join(heavy))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout.strip()
    assert out == "", f"importing {module} pulled in {out}"


def test_only_backends_import_engines():
    pattern = re.compile(r"^\s*(import|from)\s+(pybullet|sapien)\b", re.M)
    offenders = [
        str(p.relative_to(SRC))
        for p in SRC.rglob("*.py")
        if "backends" not in p.relative_to(SRC).parts and pattern.search(p.read_text())
    ]
    assert offenders == []


def _imported_modules(path: Path, package: str) -> set[str]:
    """Absolute names of every module ``path`` imports, at any depth (lazy imports included).

    Relative imports are resolved against ``package`` (the module's own
    package), so ``from ..strategies.dmg import x`` in ``benchharness.cli.run``
    counts as ``benchharness.strategies.dmg`` and, for ``from pkg import name``,
    also ``pkg.name`` (which may be a submodule).
    """
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[: len(parts) - node.level + 1])
                mod = f"{base}.{node.module}" if node.module else base
            else:
                mod = node.module or ""
            out.add(mod)
            out.update(f"{mod}.{a.name}" for a in node.names)
    return out


def test_imported_modules_resolves_relative_and_lazy_imports(tmp_path):
    """The scanner below must see a lazy relative import of a strategy, or the CLI test proves nothing."""
    src = tmp_path / "m.py"
    src.write_text("def f():\n    from ..strategies.dmg import regions\n    import os.path\n")
    found = _imported_modules(src, "benchharness.cli")
    assert {
        "benchharness.strategies.dmg",
        "benchharness.strategies.dmg.regions",
        "os.path",
    } <= found


def test_cli_imports_no_strategy():
    """No CLI module imports ``benchharness.strategies`` (docs/architecture.md, "Rules").

    The CLI is the top layer and reaches strategies only through the plugin
    manager; what it needs of stored trials (contact-region errors) is
    scoring, which lives in ``runner/``. Scans every import in ``cli/*.py``,
    including those inside functions, which a sys.modules check at start-up
    would miss.
    """
    cli_files = sorted((SRC / "cli").glob("*.py"))
    assert len(cli_files) >= 8  # main, run, inhand, ...: the scan sees the real package
    offenders = {
        p.name: sorted(
            m
            for m in _imported_modules(p, "benchharness.cli")
            if m == "benchharness.strategies" or m.startswith("benchharness.strategies.")
        )
        for p in cli_files
    }
    assert {k: v for k, v in offenders.items() if v} == {}


DOC = SRC.parents[1] / "docs" / "architecture.md"


def _packages() -> list[str]:
    """Every package directly under src/benchharness (a folder with an __init__.py)."""
    return sorted(p.parent.name for p in SRC.glob("*/__init__.py"))


def _doc_sections() -> tuple[str, str]:
    text = DOC.read_text()
    diagram = text.split("```", 2)[1]  # the layer diagram is the page's first code block
    table = text.split("## Where things live", 1)[1].split("\n## ", 1)[0]
    return diagram, table


def test_architecture_doc_names_every_package():
    """The layer diagram and the table each name every package (``name/``)."""
    packages = _packages()
    assert len(packages) >= 12  # backends ... strategies: the test must see the real tree
    diagram, table = _doc_sections()
    missing_diagram = [p for p in packages if re.search(rf"\b{p}/", diagram) is None]
    missing_table = [p for p in packages if f"src/benchharness/{p}/" not in table]
    assert missing_diagram == [], f"not in the layer diagram: {missing_diagram}"
    assert missing_table == [], f"not in the 'Where things live' table: {missing_table}"


def test_architecture_doc_names_every_top_level_module():
    modules = sorted(p.name for p in SRC.glob("*.py") if p.name != "__init__.py")
    _, table = _doc_sections()
    assert [m for m in modules if m not in table] == []


def test_where_is_x_decided_cites_code_that_exists():
    """Every ``path.py``: ``name`` cited in the index names a module and a name defined in it."""
    text = DOC.read_text().split("## Where is X decided", 1)[1].split("\n## ", 1)[0]
    cites = re.findall(r"`([a-z0-9_/]+\.py)`: `([A-Za-z_][\w.]*)", text)
    assert len(cites) >= 10
    for path, name in cites:
        assert (SRC / path).is_file(), f"{path} does not exist"
        source = (SRC / path).read_text()
        last = name.split(".")[-1]
        assert re.search(rf"^\s*(def|class)\s+{last}\b", source, re.M), f"{path} defines no {name}"


def test_no_pointer_to_a_missing_design_file():
    """Comments and docs cite pages that are in the repository (the old DESIGN.md is not)."""
    root = SRC.parents[1]
    offenders = [
        str(p.relative_to(root))
        for folder in ("src", "plugins", "tests", "docs", "examples")
        for p in (root / folder).rglob("*")
        if p.suffix in {".py", ".md"} and "build" not in p.parts and "DESIGN.md" in p.read_text()
    ]
    offenders = [o for o in offenders if o != "tests/test_architecture.py"]
    assert offenders == []
