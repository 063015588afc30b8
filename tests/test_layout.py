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

# The floors, bottom to top: a module imports only its own unit and units below it, that is folders on lower rows
# and, in its own folder, the sub-packages listed before its own. Each folder lists its sub-packages in pipeline
# order; "" stands for the folder's own top-level modules. The ground floor holds the base types and plumbing
# (errors, controls, frames, files, flag helpers); the roof is the command line.
FLOORS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("gesturecast", ("",)),
    ("gesturecast.models", ("motion", "audio", "generator", "style", "networks", "runtime", "dataset", "training",
                            "export", "evaluation")),
    ("gesturecast.bridges", ("",)),
    ("gesturecast.settings", ("",)),
    ("gesturecast.realtime", ("timing", "audio", "generation", "words", "gestures", "pose", "run", "agents",
                              "cli_flags", "jobs", "serve", "engine_cli")),
    ("gesturecast.api", ("",)),
    ("gesturecast.pipecat", ("",)),
    ("gesturecast.tools", ("render", "", "gestures", "eval", "bench")),
    ("gesturecast.cli", ("",)),
)
BASE_TYPES = ("gesturecast.errors", "gesturecast.controls", "gesturecast.frames")  # import nothing of the project
BASE_ERROR = "gesturecast.errors"  # but the base error (a refused control is a UserError)
TORCH_PACKAGES = ("gesturecast.models.networks", "gesturecast.models.training", "gesturecast.models.export",
                  "gesturecast.models.evaluation", "gesturecast.tools.bench")
LIVE_RUNTIME = ("gesturecast.realtime", "gesturecast.bridges", "gesturecast.models.runtime", "gesturecast.models.audio",
                "gesturecast.frames", "gesturecast.controls")
NEVER_LIVE = ("gesturecast.models.networks", "gesturecast.models.training", "gesturecast.models.export",
              "gesturecast.models.evaluation", "gesturecast.models.dataset", "gesturecast.tools")
# folders whose modules import nothing of gesturecast.realtime: the model side and the outputs stand without it
WITHOUT_REALTIME = ("models", "bridges")
MAX_MODULES_PER_FOLDER = 20
LIBRARY_ROOTS = ("gesturecast", "models", "realtime", "bridges")  # what ``gesturecast.*`` users import


def within(module: str, package: str) -> bool:
    return module == package or module.startswith(package + ".")


def floor_of(module: str) -> tuple[int, int]:
    """(row, place in the row's pipeline) of ``module``'s unit in FLOORS."""
    rows = [index for index, (folder, _) in enumerate(FLOORS) if within(module, folder)]
    if not rows:
        raise AssertionError(f"{module} lies in no folder of the layout table")
    row = max(rows, key=lambda index: len(FLOORS[index][0]))
    folder, units = FLOORS[row]
    rest = module[len(folder) + 1:].split(".")[0] if module != folder else ""
    unit = rest if rest in units else ""
    if unit not in units:
        raise AssertionError(f"{module}: {folder}.{rest} is not in the layout table; add it to {folder}'s units in "
                             "pipeline order")
    return row, units.index(unit)


def floor_name(module: str) -> str:
    row, place = floor_of(module)
    folder, units = FLOORS[row]
    return ".".join(part for part in (folder.removeprefix("gesturecast.") if row else folder, units[place]) if part)


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
    """Imports of torch outside the torch packages, and of a unit that is not below the importer's (lazy ones too)."""
    problems = []
    for module, imported in graph.items():
        here = floor_of(module)
        for target in imported:
            if target == "torch" and not module.startswith(TORCH_PACKAGES):
                problems.append(f"{module} imports torch ({floor_name(module)} is torch-free)")
            if not target.startswith("gesturecast") or floor_of(target) == here:
                continue
            if floor_of(target) > here:
                problems.append(f"{module} ({floor_name(module)}) imports {target} ({floor_name(target)}, above it)")
    return problems


def import_cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The project's import circles: each a list of modules that import one another round (Tarjan's strongly
    connected components of more than one module, or a module importing itself)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    cycles = []

    def visit(module: str) -> None:
        index[module] = low[module] = len(index)
        stack.append(module)
        for target in sorted(graph.get(module, ())):
            if target not in graph:
                continue
            if target not in index:
                visit(target)
                low[module] = min(low[module], low[target])
            elif target in stack:
                low[module] = min(low[module], index[target])
        if low[module] == index[module]:
            component = stack[stack.index(module):]
            del stack[stack.index(module):]
            if len(component) > 1 or module in graph[module]:
                cycles.append(sorted(component))

    for module in sorted(graph):
        if module not in index:
            visit(module)
    return cycles


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


def test_no_modules_import_one_another_round(graph):
    assert import_cycles(graph) == []


def test_the_base_types_import_nothing_of_the_project_but_the_base_error(graph):
    assert {module: sorted(t for t in graph.get(module, ()) if t.startswith("gesturecast") and t != BASE_ERROR)
            for module in BASE_TYPES} == {module: [] for module in BASE_TYPES}


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
    assert "gesturecast.models.generator.helper imports torch (models.generator is torch-free)" in (
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
        "gesturecast.models.motion.skeleton (models.motion) imports gesturecast.realtime.pose.session (realtime.pose, "
        "above it)",
    ]
    assert "gesturecast.realtime.pose.session reaches gesturecast.models.training.pipeline (through " \
           "gesturecast.realtime.pose.session)" in live_runtime_violations(graph)


def test_the_checks_catch_a_lazy_import_going_back_up_and_an_import_circle(tmp_path):
    graph = _tree(tmp_path, {
        "realtime/cli_flags.py": "def config():\n    from gesturecast.realtime.serve.server import ServeConfig\n",
        "realtime/serve/server.py": "ServeConfig = None\n",
        "realtime/serve/serve_command.py": "from gesturecast.realtime.serve.ray_cli import add_ray_arguments\n",
        "realtime/serve/ray_cli.py": "def app():\n    from gesturecast.realtime.serve.ray_replica import replica\n",
        "realtime/serve/ray_replica.py": "from gesturecast.realtime.serve.serve_command import add_serve_arguments\n",
    })
    assert floor_violations(graph) == [
        "gesturecast.realtime.cli_flags (realtime.cli_flags) imports gesturecast.realtime.serve.server "
        "(realtime.serve, above it)",
    ]
    assert import_cycles(graph) == [["gesturecast.realtime.serve.ray_cli", "gesturecast.realtime.serve.ray_replica",
                                     "gesturecast.realtime.serve.serve_command"]]


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
