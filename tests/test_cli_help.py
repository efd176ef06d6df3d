"""Every option and argument of every ``rocklab`` command says what it is for (``--help``)."""

from __future__ import annotations

import argparse

from rocklab.pipelines.cli._cli import build_parser


def _walk(parser, path):
    for a in parser._actions:
        if isinstance(a, argparse._SubParsersAction):
            for name, sub in a.choices.items():
                yield from _walk(sub, (*path, name))
        elif not isinstance(a, (argparse._HelpAction, argparse._VersionAction)):
            yield path, a


def test_every_option_of_every_command_has_help():
    actions = list(_walk(build_parser(), ("rocklab",)))
    commands = {p for p, _ in actions}
    # the walk reaches the nested commands (fit restitution, equivalent, track) and their options
    assert {("rocklab", "fit", "restitution"), ("rocklab", "oas"), ("rocklab", "track")} <= commands
    assert len(actions) > 200
    missing = [
        f"{' '.join(p)} {'/'.join(a.option_strings) or a.dest}" for p, a in actions if not (a.help or "").strip()
    ]
    assert missing == []
