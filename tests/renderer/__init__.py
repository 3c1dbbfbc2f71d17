"""Tests of roughsea_torch/renderer/, a file a module (tests/conftest.py describes the layout)."""
