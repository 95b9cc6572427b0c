"""The manual's [choice]s as command-line options, shared by every command that speaks
the robot's protocol (`frame`, `emulate`): one definition, one set of help texts."""
from __future__ import annotations

import functools

import click

from verifier.commands.numbers import IntRange
from verifier.protocol.settings import CODES_10_13_STYLES, FIELD_ORDERS, STATUS_ORDERS, Settings

_OPTIONS = (
    click.option("--address", type=IntRange(1, 247), default=1, show_default=True,
                 help="Robot (slave) address."),
    click.option("--field-order", type=click.Choice(FIELD_ORDERS), default="code-high", show_default=True,
                 help="FC06 register field: control code in the high byte (manual text) "
                      "or low byte (its examples)."),
    click.option("--codes-10-13", "codes_10_13", type=click.Choice(CODES_10_13_STYLES), default="decimal",
                 show_default=True,
                 help="Control codes 10-13 on the wire as 0x0A-0x0D (decimal) or 0x10-0x13 (hex)."),
    click.option("--status-order", type=click.Choice(STATUS_ORDERS), default="query", show_default=True,
                 help="FC01 query numbering: 0 task, 1 vehicle, 2 speed, 3 battery (query) "
                      "or 0 speed, 1 battery, 2 task, 3 vehicle (return)."),
    click.option("--manual-stop-counts-as-stop", is_flag=True,
                 help="Accept manual stop 05/00 as the power-on stop command."),
)
_NAMES = ("address", "field_order", "codes_10_13", "status_order", "manual_stop_counts_as_stop")


def given_settings(settings: Settings) -> dict:
    """Those of `settings` given on the command line (not left at their defaults), by field."""
    context = click.get_current_context()
    return {name: getattr(settings, name) for name in _NAMES
            if context.get_parameter_source(name) is not click.core.ParameterSource.DEFAULT}


def protocol_settings(command):
    """Add the protocol setting options to a click command and hand it one `settings`
    keyword argument (a `verifier.protocol.Settings`) instead of five loose values."""

    @functools.wraps(command)
    def with_settings(*args, **kwargs):
        chosen = {name: kwargs.pop(name) for name in _NAMES}
        try:
            settings = Settings(**chosen)
        except ValueError as err:
            raise click.UsageError(str(err)) from None
        return command(*args, settings=settings, **kwargs)

    for option in reversed(_OPTIONS):
        with_settings = option(with_settings)
    return with_settings
