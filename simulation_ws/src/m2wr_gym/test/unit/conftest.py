"""Shared fixtures of m2wr_gym's unit tests (no ROS master)."""
import logging

import pytest


@pytest.fixture(autouse=True)
def _quiet_logs():
    logging.getLogger("m2wr_gym").setLevel(logging.CRITICAL)
    yield
