"""The layout's rule, checked on the import graph (docs/layout.md): lower floors never import upper ones,
torch only where training happens, and the live runtime reaches no torch and nothing of training.

Imports are read with ``ast`` (inside functions too), so a lazy import counts like any other.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[1]
# source folder -> import name (pyproject.toml's package-dir)
SOURCE_ROOTS = {"gesturecast": "gesturecast", "models": "gesturecast.models", "realtime": "gesturecast.realtime",
                "bridges": "gesturecast.bridges", "tools": "gesturecast.tools"}

# package -> floor: a module imports only its own package and packages on lower floors
FLOORS = {
    "gesturecast.errors": 0,
    "gesturecast.files": 1,
    "gesturecast.arguments": 1,
    "gesturecast.models.motion": 2,
    "gesturecast.models.generator": 2,
    "gesturecast.realtime.timing": 3,
    "gesturecast.models.networks": 3,
    "gesturecast.realtime.audio": 4,
    "gesturecast.realtime.features": 5,
    "gesturecast.models.dataset": 5,
    "gesturecast.models.runtime": 6,
    "gesturecast.bridges": 6,
    "gesturecast.tools.render": 6,
    "gesturecast.realtime": 7,
    "gesturecast.realtime.serve": 8,
    "gesturecast.realtime.agents": 8,
    "gesturecast.models.training": 8,
    "gesturecast.models.export": 9,
    "gesturecast.models.evaluation": 9,
    "gesturecast.tools": 10,
    "gesturecast.tools.eval": 11,
    "gesturecast.tools.bench": 12,
    "gesturecast.cli": 13,
}
TORCH_PACKAGES = {"gesturecast.models.networks", "gesturecast.models.training", "gesturecast.models.export",
                  "gesturecast.models.evaluation", "gesturecast.tools.bench"}
LIVE_RUNTIME = ("gesturecast.realtime", "gesturecast.bridges", "gesturecast.models.runtime")
NEVER_LIVE = ("gesturecast.models.networks", "gesturecast.models.training", "gesturecast.models.export",
              "gesturecast.models.evaluation", "gesturecast.models.dataset", "gesturecast.tools")
MAX_MODULES_PER_FOLDER = 20


def package_of(module: str) -> str:
    """The longest package of FLOORS that holds ``module``."""
    owners = [name for name in FLOORS if module == name or module.startswith(name + ".")]
    if not owners:
        raise AssertionError(f"{module} lies in no package of the layout table")
    return max(owners, key=len)


def module_name(path: Path, roots: dict[str, str]) -> str:
    parts = path.with_suffix("").parts
    name = [roots[parts[0]], *parts[1:]]
    return ".".join(name[:-1] if name[-1] == "__init__" else name)


def read_imports(path: Path) -> set[str]:
    """Every module that ``path`` imports, anywhere in the file (absolute names)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            assert node.level == 0, f"{path}: relative import; the layout uses absolute imports"
            found.add(node.module)
            found.update(f"{node.module}.{alias.name}" for alias in node.names)  # `from pkg import module`
    return found


def import_graph(repo: Path, roots: dict[str, str]) -> dict[str, set[str]]:
    """module -> the project modules and top-level third-party names it imports (a package's ``__init__``
    that imports nothing, like ``gesturecast.models``, is no node)."""
    files = {module_name(p.relative_to(repo), roots): p for root in roots for p in (repo / root).rglob("*.py")}
    graph = {}
    for module, path in files.items():
        imported = read_imports(path)
        if path.name == "__init__.py" and not imported:
            continue
        graph[module] = {name for name in imported if name in files} | {
            name.split(".")[0] for name in imported if not name.startswith("gesturecast")}
    return graph


def floor_violations(graph: dict[str, set[str]]) -> list[str]:
    problems = []
    for module, imported in graph.items():
        here = package_of(module)
        for target in imported:
            if target == "torch" and here not in TORCH_PACKAGES:
                problems.append(f"{module} imports torch ({here} is torch-free)")
            if not target.startswith("gesturecast"):
                continue
            there = package_of(target)
            if there != here and FLOORS[there] >= FLOORS[here]:
                problems.append(f"{module} (floor {FLOORS[here]}) imports {target} (floor {FLOORS[there]})")
    return problems


def live_runtime_violations(graph: dict[str, set[str]]) -> list[str]:
    """What the live runtime reaches, transitively, that it must not: torch, training, evaluation, export."""
    problems, seen = [], set()
    todo = [(m, m) for m in graph if m.startswith(LIVE_RUNTIME) and not m.startswith(NEVER_LIVE)]
    while todo:
        module, via = todo.pop()
        if module in seen:
            continue
        seen.add(module)
        for target in graph.get(module, ()):
            if target == "torch" or target.startswith(NEVER_LIVE):
                problems.append(f"{via} reaches {target} (through {module})")
            elif target in graph:
                todo.append((target, via))
    return problems


@pytest.fixture(scope="module")
def graph() -> dict[str, set[str]]:
    return import_graph(REPO_ROOT, SOURCE_ROOTS)


def test_every_package_lies_on_a_floor_and_imports_only_lower_floors(graph):
    assert floor_violations(graph) == []


def test_the_live_runtime_reaches_no_torch_and_nothing_of_training(graph):
    assert live_runtime_violations(graph) == []


def test_no_package_folder_holds_more_than_twenty_modules():
    crowded = {str(folder.relative_to(REPO_ROOT)): count
               for root in SOURCE_ROOTS for folder in [REPO_ROOT / root, *(REPO_ROOT / root).rglob("*/")]
               if (count := len([p for p in folder.glob("*.py") if p.name != "__init__.py"])) > MAX_MODULES_PER_FOLDER}
    assert crowded == {}


def _tree(tmp_path: Path, files: dict[str, str]) -> dict[str, set[str]]:
    for relative, text in files.items():
        path = tmp_path / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return import_graph(tmp_path, SOURCE_ROOTS)


def test_the_checks_catch_torch_in_the_runtime_even_through_a_helper(tmp_path):
    graph = _tree(tmp_path, {
        "models/runtime/bundle.py": "from gesturecast.models.generator.helper import f\n",
        "models/generator/helper.py": "def f():\n    import torch\n",
        "realtime/session.py": "from gesturecast.models.runtime.bundle import x\n",
    })
    assert "gesturecast.models.generator.helper imports torch (gesturecast.models.generator is torch-free)" in (
        floor_violations(graph))
    assert "gesturecast.realtime.session reaches torch (through gesturecast.models.generator.helper)" in (
        live_runtime_violations(graph))


def test_the_checks_catch_an_upward_import_and_training_in_the_runtime(tmp_path):
    graph = _tree(tmp_path, {
        "models/motion/skeleton.py": "from gesturecast.realtime.session import x\n",
        "realtime/session.py": "from gesturecast.models.training import pipeline\n",
        "models/training/pipeline.py": "import torch\n",
    })
    assert floor_violations(graph) == [
        "gesturecast.models.motion.skeleton (floor 2) imports gesturecast.realtime.session (floor 7)",
        "gesturecast.realtime.session (floor 7) imports gesturecast.models.training.pipeline (floor 8)",
    ]
    assert "gesturecast.realtime.session reaches gesturecast.models.training.pipeline (through " \
           "gesturecast.realtime.session)" in live_runtime_violations(graph)
