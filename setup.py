"""Package layout: the top-level folders are subpackages of ``zenav``.

``schemas/``, ``services/`` and ``sim/`` sit at the repository root (the system's shape),
yet import as ``zenav.schemas``, ``zenav.services`` and ``zenav.sim``: setuptools maps each
folder onto its package name, in a regular install and in an editable one alike.
Everything else about the distribution is in ``pyproject.toml``.
"""

from setuptools import find_packages, setup

# import name -> folder, for every top-level package of the distribution
ROOTS = {"zenav": "zenav", "zenav.schemas": "schemas", "zenav.services": "services",
         "zenav.sim": "sim"}


def _packages() -> list[str]:
    names: list[str] = []
    for package, folder in ROOTS.items():
        names.append(package)
        names += [f"{package}.{sub}" for sub in find_packages(folder)]
    return names


setup(packages=_packages(), package_dir=ROOTS)
