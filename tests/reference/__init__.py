"""Tests of the numpy reference alone (roughsea_torch/reference/), a file a module."""
