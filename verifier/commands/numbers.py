"""Whole-number options that take the digits 0-9 only: click's INT and IntRange convert
with int(), which reads '１２' and '١٢' as 12 (verifier.digits)."""
from __future__ import annotations

import click

from verifier.digits import digit_problem


class _Digits:
    def convert(self, value, param, ctx):
        if isinstance(value, str) and (problem := digit_problem(value)):
            self.fail(problem, param, ctx)
        return super().convert(value, param, ctx)


class Int(_Digits, click.types.IntParamType):
    """click.INT, for the digits 0-9 only."""


class IntRange(_Digits, click.IntRange):
    """click.IntRange, for the digits 0-9 only."""


INT = Int()
