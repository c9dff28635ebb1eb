"""Maps the repository's stage folders into the one import namespace ``sgtool``.

``toolkit/`` is ``sgtool``; ``recorders/``, ``replayers/``, ``datasets/`` and ``analysis/``
are ``sgtool.recorders`` and so on (see DESIGN.md). Everything else is in pyproject.toml.
"""

from setuptools import find_packages, setup

ROOTS = {
    "sgtool": "toolkit",
    "sgtool.recorders": "recorders",
    "sgtool.replayers": "replayers",
    "sgtool.datasets": "datasets",
    "sgtool.analysis": "analysis",
}

packages: list[str] = []
package_dir: dict[str, str] = {}
for name, folder in ROOTS.items():
    packages.append(name)
    package_dir[name] = folder
    for sub in find_packages(folder):
        packages.append(f"{name}.{sub}")
        package_dir[f"{name}.{sub}"] = f"{folder}/{sub.replace('.', '/')}"

setup(packages=packages, package_dir=package_dir)
