"""docs/HAMLIB.md (#34 item 16) names every state STATUS can show for the rotor and the radio, and no other:
the words are read from the code's ``link_state`` methods (their returned string literals), not copied."""

from __future__ import annotations

import ast
import inspect
import re
import textwrap

from nfwserver.radio.coupling import RadioCoupling
from nfwserver.rotor.kct_rotor_link import KctRotorLink
from tests.conftest import ROOT


def _returned_words(method: object) -> set[str]:
    tree = ast.parse(textwrap.dedent(inspect.getsource(method)))  # type: ignore[arg-type]
    words: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Return) and node.value is not None:
            words |= {n.value for n in ast.walk(node.value) if isinstance(n, ast.Constant) and isinstance(n.value, str)}
    return words


def _documented(field: str) -> set[str]:
    text = (ROOT / "docs" / "HAMLIB.md").read_text(encoding="utf-8")
    table = text.split(f"| `{field}=` | meaning |", 1)[1].split("\n\n", 1)[0]
    return set(re.findall(r"^\| `([a-z-]+)` \|", table, re.MULTILINE))


def test_every_rotor_and_radio_state_is_documented() -> None:
    assert _documented("rotor") == _returned_words(KctRotorLink.link_state)
    assert _documented("radio") == _returned_words(RadioCoupling.link_state)
