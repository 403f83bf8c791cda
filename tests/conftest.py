"""Settings for every test.

Property tests (hypothesis) run with no per-example deadline and a fixed seed: the
machines that run them are shared and often loaded, so a wall-clock deadline fails for
reasons that have nothing to do with the code, and a failure must be reproducible by
running the same command again.
"""

from hypothesis import settings

settings.register_profile("zenav", deadline=None, derandomize=True, database=None)
settings.load_profile("zenav")
