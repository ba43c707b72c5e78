"""Shared test set-up: one Taichi backend (CPU, f32) for the whole session.

Only ``crowndemo.backend.init`` starts Taichi. The determinism test re-initialises with one
thread and a fixed seed and puts the default backend back afterwards.
"""
import pytest

from crowndemo import backend


@pytest.fixture(scope="session", autouse=True)
def taichi_backend():
    return backend.init("cpu")
