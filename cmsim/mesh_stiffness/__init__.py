"""Mesh stiffness: tooth geometry, contact geometry kernels, stiffness tables."""
