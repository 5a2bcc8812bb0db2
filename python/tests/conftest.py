"""Shared fixtures: the Rust reference numbers that crates/xylem-cli/tests/python.rs writes before running pytest."""

import json
import os
import pathlib

import pytest

ROOT = pathlib.Path(os.environ.get("XYLEM_ROOT", pathlib.Path(__file__).resolve().parents[2]))


@pytest.fixture(scope="session")
def reference():
    path = os.environ.get("XYLEM_REFERENCE")
    if not path:
        pytest.skip("XYLEM_REFERENCE not set: run through `cargo test --release --test python`")
    with open(path) as f:
        return json.load(f)


@pytest.fixture(scope="session")
def root():
    return ROOT
