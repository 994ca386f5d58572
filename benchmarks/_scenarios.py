"""Scenario files the benchmarks time (one writer for the impacts several scripts use)."""

from __future__ import annotations


def impact_toml(n: int, front: int) -> str:
    """A paper-grain impact (v0 = 1 m/s, δ0 = 0) on ``n`` grains, run until the front
    reaches grain ``front``, recording running maxima: a scenario TOML for
    ``hertzchain run``."""
    return f"""\
name = "impact{n}"
[chain]
delta0_over_d = 0.0
[[chain.sections]]
n = {n}
[initial]
kind = "impact"
v0 = 1.0
[run]
until_front_at = {front}
[record]
running_max = true
"""
