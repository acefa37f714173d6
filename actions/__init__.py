"""Composition and execution: service resource graph, plans, component container.

Empty until the composition work lands; see docs/architecture.md for where it fits.
"""
