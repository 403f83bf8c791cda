"""Planner: collision prediction, the paper's responses and simplified Morphin."""
