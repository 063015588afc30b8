"""The package list for pyproject.toml's folder layout; everything else about the project is in pyproject.toml.

``[tool.setuptools] package-dir`` maps folders to import names (realtime/ is ``gesturecast.realtime``, and so on),
which setuptools' own ``find`` cannot follow. Here every folder below a mapped folder that has an ``__init__.py`` is a
package, so a new subpackage cannot be left out of the wheel; and every folder holding files that
``[tool.setuptools.package-data]`` ships (the weights, the viewer page and its avatar, the sample) is declared as a
data-only package, as setuptools wants data folders declared. A folder with neither (e.g. tools/viewer_bundle, the
viewer bundle's npm sources) is not shipped.
"""

from __future__ import annotations

from pathlib import Path

from setuptools import find_packages, setup

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10: pyproject.toml's build-system.requires brings tomli
    import tomli as tomllib

ROOT = Path(__file__).resolve().parent


def folder_of(package: str, package_dir: dict[str, str]) -> Path:
    """The source folder of ``package``, through the longest mapped prefix of its name."""
    parts = package.split(".")
    for depth in range(len(parts), 0, -1):
        mapped = package_dir.get(".".join(parts[:depth]))
        if mapped is not None:
            return ROOT / mapped / Path(*parts[depth:])
    return ROOT / Path(*parts)


def code_packages(package_dir: dict[str, str]) -> set[str]:
    """Each mapped package and every folder below its folder that has an ``__init__.py``."""
    found = set(package_dir)
    for package, folder in package_dir.items():
        found.update(f"{package}.{sub}" for sub in find_packages(str(ROOT / folder)))
    return found


def data_packages(package_dir: dict[str, str], package_data: dict[str, list[str]]) -> set[str]:
    """The folders, as package names, that hold files the ``package_data`` patterns match."""
    found = set()
    for package, patterns in package_data.items():
        if package == "*":  # a pattern for every package names no folder of its own
            continue
        folder = folder_of(package, package_dir)
        for pattern in patterns:
            for path in folder.glob(pattern):
                parts = path.relative_to(folder).parent.parts
                if not path.is_file() or path.name.startswith(".") or "__pycache__" in parts:
                    continue
                for depth in range(1, len(parts) + 1):
                    if not parts[depth - 1].isidentifier():
                        break
                    found.add(".".join((package, *parts[:depth])))
    return found


def packages() -> list[str]:
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"]
    package_dir, package_data = config["package-dir"], config.get("package-data", {})
    return sorted(code_packages(package_dir) | data_packages(package_dir, package_data))


setup(packages=packages())
