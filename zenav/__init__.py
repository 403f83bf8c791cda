"""zenav: mobile-robot navigation among static and moving obstacles, as Zenoh services.

The subpackages ``zenav.schemas``, ``zenav.services`` and ``zenav.sim`` live in the
repository's top-level folders ``schemas/``, ``services/`` and ``sim/``.
"""

__version__ = "0.1.0"
