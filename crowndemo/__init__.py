"""crowndemo: the milk crown by the explicit MPS method, in Taichi."""
__version__ = "0.1.0"
