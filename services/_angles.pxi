# The angle wrap of geometry.py for the compiled loops (Cython), written once here and
# included where it is used. _angles.pyx exposes it to Python so that the tests pin it
# to geometry.wrap_angles, value for value.
from libc.math cimport M_PI


cdef inline double wrap_angle(double angle):
    """The same angle (rad) in (-pi, pi], by the operations of ``geometry.wrap_angles``
    (Python's ``%`` on doubles)."""
    cdef double wrapped = (angle + M_PI) % (2.0 * M_PI) - M_PI
    return wrapped + 2.0 * M_PI if wrapped <= -M_PI else wrapped
