"""UITAMR PLC toolkit verifier: parse GX Works ST, simulate it, check its robot traffic."""

__version__ = "0.1.0"
