"""The pybullet home and the simulation-backed components.

Empty until the execution work lands; see docs/architecture.md for where it fits.
"""
