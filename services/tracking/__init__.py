"""Tracking: obstacle types (new / static / dynamic), persistent ids and obstacle motion.

The paper's equations (Eqs. 7-15 and the decision tree) are small pure functions in
:mod:`zenav.services.tracking.correlation`; :mod:`zenav.services.tracking.tracker` keeps the
state between frames; :mod:`zenav.services.tracking.params` holds every parameter.
"""
