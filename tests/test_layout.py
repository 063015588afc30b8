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

# package -> floor: a module imports only its own package and packages on lower floors. ``gesturecast`` holds the
# shared plumbing (errors, the pose-frame contract, file and flag helpers); realtime's subpackages share its row.
FLOORS = {
    "gesturecast": 0,
    "gesturecast.models.motion": 1,
    "gesturecast.models.generator": 1,
    "gesturecast.models.audio": 1,
    "gesturecast.models.networks": 2,
    "gesturecast.settings": 2,
    "gesturecast.models.dataset": 3,
    "gesturecast.models.runtime": 4,
    "gesturecast.bridges": 4,
    "gesturecast.tools.render": 4,
    "gesturecast.realtime": 5,
    "gesturecast.models.training": 5,
    "gesturecast.api": 6,
    "gesturecast.pipecat": 6,
    "gesturecast.models.export": 6,
    "gesturecast.models.evaluation": 6,
    "gesturecast.tools": 7,
    "gesturecast.tools.eval": 8,
    "gesturecast.tools.bench": 9,
    "gesturecast.cli": 10,
}
TORCH_PACKAGES = {"gesturecast.models.networks", "gesturecast.models.training", "gesturecast.models.export",
                  "gesturecast.models.evaluation", "gesturecast.tools.bench"}
LIVE_RUNTIME = ("gesturecast.realtime", "gesturecast.bridges", "gesturecast.models.runtime", "gesturecast.models.audio",
                "gesturecast.frames")
NEVER_LIVE = ("gesturecast.models.networks", "gesturecast.models.training", "gesturecast.models.export",
              "gesturecast.models.evaluation", "gesturecast.models.dataset", "gesturecast.tools")
# folders whose modules import nothing of gesturecast.realtime: the model side and the outputs stand without it
WITHOUT_REALTIME = ("models", "bridges")
MAX_MODULES_PER_FOLDER = 20
LIBRARY_ROOTS = ("gesturecast", "models", "realtime", "bridges")  # what ``gesturecast.*`` users import


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


def realtime_imports(repo: Path, folders: tuple[str, ...]) -> list[str]:
    """Every import of ``gesturecast.realtime`` (anywhere in a file) by a module under ``folders``."""
    return [f"{path.relative_to(repo)} imports {name}"
            for folder in folders for path in sorted((repo / folder).rglob("*.py"))
            for name in sorted(read_imports(path)) if name.split(".")[:2] == ["gesturecast", "realtime"]]


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


def test_models_and_bridges_import_nothing_of_realtime():
    assert realtime_imports(REPO_ROOT, WITHOUT_REALTIME) == []


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
        "realtime/pose/session.py": "from gesturecast.models.runtime.bundle import x\n",
    })
    assert "gesturecast.models.generator.helper imports torch (gesturecast.models.generator is torch-free)" in (
        floor_violations(graph))
    assert "gesturecast.realtime.pose.session reaches torch (through gesturecast.models.generator.helper)" in (
        live_runtime_violations(graph))


def test_the_checks_catch_an_upward_import_and_training_in_the_runtime(tmp_path):
    graph = _tree(tmp_path, {
        "models/motion/skeleton.py": "from gesturecast.realtime.pose.session import x\n",
        "realtime/pose/session.py": "from gesturecast.models.training import pipeline\n",
        "models/training/pipeline.py": "import torch\n",
    })
    assert floor_violations(graph) == [
        "gesturecast.models.motion.skeleton (floor 1) imports gesturecast.realtime.pose.session (floor 5)",
        "gesturecast.realtime.pose.session (floor 5) imports gesturecast.models.training.pipeline (floor 5)",
    ]
    assert "gesturecast.realtime.pose.session reaches gesturecast.models.training.pipeline (through " \
           "gesturecast.realtime.pose.session)" in live_runtime_violations(graph)


def test_the_check_catches_a_lazy_realtime_import_in_the_bridges(tmp_path):
    _tree(tmp_path, {
        "bridges/osc.py": "def send():\n    from gesturecast.realtime.pose import session\n",
        "bridges/vmc.py": "import gesturecast.frames\n",
        "models/audio/files.py": "from gesturecast.errors import UserError\n",
    })
    assert realtime_imports(tmp_path, WITHOUT_REALTIME) == [
        "bridges/osc.py imports gesturecast.realtime.pose",
        "bridges/osc.py imports gesturecast.realtime.pose.session",
    ]


def mentions_namespace(tree: ast.AST) -> bool:
    """Whether the code names ``argparse.Namespace`` (an annotation, a call, an import)."""
    return any((isinstance(node, ast.Attribute) and node.attr == "Namespace")
               or (isinstance(node, ast.alias) and node.name == "Namespace") for node in ast.walk(tree))


def builds_namespace(tree: ast.AST) -> bool:
    """Whether the code makes a Namespace (copying and patching parsed flags instead of changing settings)."""
    return any(isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "Namespace"
               for node in ast.walk(tree))


def is_command_module(path: Path, tree: ast.Module) -> bool:
    """A command-line module: named ``*cli*``, or one that registers a (bench) sub-command."""
    registers = any(isinstance(node, ast.FunctionDef) and node.name in ("register", "register_bench")
                    for node in tree.body)
    return "cli" in path.stem or registers


def namespace_violations(repo: Path) -> list[str]:
    """Library modules that take parsed flags, and any module that copies and patches them. ``tools/`` holds only
    commands (benchmarks, evaluation, data preparation), so its modules may take flags but never copy them."""
    problems = []
    for path in sorted(p for root in SOURCE_ROOTS for p in (repo / root).rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        where = str(path.relative_to(repo))
        library = path.relative_to(repo).parts[0] in LIBRARY_ROOTS
        if library and mentions_namespace(tree) and not is_command_module(path, tree):
            problems.append(f"{where} handles argparse.Namespace outside the command line (take Settings)")
        if builds_namespace(tree):
            problems.append(f"{where} builds an argparse.Namespace (use Settings.replace / settings_from_args)")
    return problems


def test_parsed_flags_stay_in_command_modules_and_are_never_copied_and_patched():
    assert namespace_violations(REPO_ROOT) == []


def test_the_namespace_check_catches_a_library_module_and_a_copied_namespace(tmp_path):
    for relative, text in {
        "realtime/run/engine_setup.py": "import argparse\ndef build(args: argparse.Namespace): ...\n",
        "tools/bench/latency.py": "import argparse\ndef run(args: argparse.Namespace): ...\n"
                                  "def f(args): return argparse.Namespace(**vars(args))\n",
    }.items():
        (tmp_path / relative).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / relative).write_text(text)
    assert namespace_violations(tmp_path) == [
        "realtime/run/engine_setup.py handles argparse.Namespace outside the command line (take Settings)",
        "tools/bench/latency.py builds an argparse.Namespace (use Settings.replace / settings_from_args)",
    ]
