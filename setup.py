"""Package layout: the top-level folders are subpackages of ``zenav``.

``schemas/``, ``services/`` and ``sim/`` sit at the repository root (the system's shape),
yet import as ``zenav.schemas``, ``zenav.services`` and ``zenav.sim``: setuptools maps each
folder onto its package name, in a regular install and in an editable one alike.

A few hot loops (``services/motor_bridge/_loops.pyx``, ``services/perception/_loops.pyx``,
``services/planner/_loops.pyx``, ``services/tracking/_loops.pyx``, and the angle wrap
the perception's and the planner's share, ``services/_angles.pxi``) are compiled here
with Cython, at install: an install from source needs a C compiler.
Everything else about the distribution is in ``pyproject.toml``.
"""

from Cython.Build import cythonize
from setuptools import Extension, find_packages, setup

# import name -> folder, for every top-level package of the distribution
ROOTS = {"zenav": "zenav", "zenav.schemas": "schemas", "zenav.services": "services",
         "zenav.sim": "sim"}

EXTENSIONS = [Extension("zenav.services._angles", ["services/_angles.pyx"])] + [
    Extension(f"zenav.services.{name}._loops", [f"services/{name}/_loops.pyx"])
    for name in ("motor_bridge", "perception", "planner", "tracking")]


def _packages() -> list[str]:
    names: list[str] = []
    for package, folder in ROOTS.items():
        names.append(package)
        names += [f"{package}.{sub}" for sub in find_packages(folder)]
    return names


setup(packages=_packages(), package_dir=ROOTS,
      ext_modules=cythonize(EXTENSIONS, quiet=True))
