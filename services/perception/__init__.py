"""Perception: the paper's sliding window and adaptive-threshold clustering of a laser scan.

The pure algorithm lives in :mod:`zenav.services.perception.clustering` (numpy in, numpy out);
its parameters in :mod:`zenav.services.perception.params`.
"""
