"""The one club vocabulary every surface speaks: a bay PATCH, a POST /v1/shots `club`, Open Connect's Code 201 and
`golfflight fly --club` all take what a golfer types (`7i`, `7 iron`, `7-Iron`, `dr`, `3w`, `pw`, `sand wedge`,
`putter`) and GSPro's club codes (`DR`, `W3`, `H4`, `I7`, `PW`, `PT`), and name the club by its GSPro code, which is
what the bay keeps, GSPro's connectors hear (Code 201) and the session's summary groups by.

`FLIES_AS` says which tour-average launch of `shots.clubs.CLUBS` a code starts `golfflight fly` from (this floor
cannot import that one, so the launch table is named here by its names only).
"""

from __future__ import annotations

from typing import Annotated, Literal

from golfflight.errors import InputError
from pydantic import BeforeValidator, WithJsonSchema

GSPRO_CLUBS: dict[str, str] = {
    "DR": "Driver",
    **{f"W{n}": f"{n}-wood" for n in range(2, 8)},
    **{f"H{n}": f"{n}-hybrid" for n in range(2, 8)},
    **{f"I{n}": f"{n}-iron" for n in range(1, 10)},
    "PW": "Pitching wedge",
    "GW": "Gap wedge",
    "SW": "Sand wedge",
    "LW": "Lob wedge",
    "PT": "Putter",
}
"""GSPro's club codes (Open Connect's Code 201 `Player.Club`), in the bag's order, with the name a screen shows."""

PUTTER = "PT"
"""The putter's code: with it selected a connector's putt rolls on the bay's ground from the start."""

ClubCode = Literal[tuple(GSPRO_CLUBS)]

PLAIN_HYBRID = "H3"
"""The code of a hybrid named without a number (`hybrid`, `hy`, `rescue`): the tour-average launch table has one
hybrid, and every H code flies from it."""


def club_key(text: str) -> str:
    """A club name as the alias table looks it up: lower case, without spaces, hyphens, underscores or dots."""
    return "".join(ch for ch in text.strip().lower() if ch not in " \t-_.")


def _numbered(kind: str, code: str, numbers: range) -> dict[str, str]:
    """`7iron`, `7i`, `i7` (and the code's own `i7`) -> `I7` for each number of a kind of club."""
    return {alias: f"{code}{n}" for n in numbers for alias in (f"{n}{kind}", f"{n}{kind[0]}", f"{kind[0]}{n}")}


CLUB_ALIASES: dict[str, str] = {
    **{club_key(code): code for code in GSPRO_CLUBS},
    **{club_key(name): code for code, name in GSPRO_CLUBS.items()},
    **{alias: "DR" for alias in ("driver", "dr", "d", "1w", "1wood", "w1")},
    **_numbered("wood", "W", range(2, 8)),
    **_numbered("hybrid", "H", range(2, 8)),
    **{f"{n}hy": f"H{n}" for n in range(2, 8)},
    **{alias: PLAIN_HYBRID for alias in ("hybrid", "hy", "hyb", "h", "rescue")},
    **_numbered("iron", "I", range(1, 10)),
    **{alias: "PW" for alias in ("pw", "pitchingwedge", "pitching", "p")},
    **{alias: "GW" for alias in ("gw", "gapwedge", "gap", "aw", "approachwedge", "approach", "uw", "utilitywedge")},
    **{alias: "SW" for alias in ("sw", "sandwedge", "sand")},
    **{alias: "LW" for alias in ("lw", "lobwedge", "lob")},
    **{alias: PUTTER for alias in ("pt", "putter", "putt")},
}
"""What a golfer types or GSPro sends, in `club_key` form -> the GSPro code: every code and every name a screen
shows (`GSPRO_CLUBS`), and the short forms `golfflight fly` has always taken."""

ACCEPTED = (f"a GSPro club code ({', '.join(GSPRO_CLUBS)}) or a club's name in any case (driver, 3w, 7i, 7 iron, "
            "hybrid, pw, gap wedge, sw, lob wedge, putter, ...)")
"""What a refusal of an unknown club says is taken."""

FLIES_AS: dict[str, str | None] = {
    "DR": "Driver",
    **{f"W{n}": "3-wood" if n <= 4 else "5-wood" for n in range(2, 8)},
    **{f"H{n}": "Hybrid" for n in range(2, 8)},
    **{f"I{n}": "3-iron" if n <= 3 else f"{n}-iron" for n in range(1, 10)},
    **{code: code for code in ("PW", "GW", "SW", "LW")},
    PUTTER: None,
}
"""Each code's tour-average launch (`shots.clubs.CLUBS` by name) for `golfflight fly`: W2-W4 fly as the 3-wood,
W5-W7 as the 5-wood, every hybrid as the hybrid, I1-I3 as the 3-iron; the putter has none (a putt is no flight)."""


def club_code(text: object) -> str:
    """The GSPro code of a club as a golfer types it or GSPro sends it (`CLUB_ALIASES`); InputError saying what is
    taken for anything else."""
    code = CLUB_ALIASES.get(club_key(text)) if isinstance(text, str) else None
    if code is None:
        raise InputError(f"unknown club {text!r}: give {ACCEPTED}")
    return code


ClubName = Annotated[
    ClubCode,
    BeforeValidator(club_code),
    WithJsonSchema({"type": "string", "description": f"the club: {ACCEPTED}; kept and answered as its GSPro code"},
                   mode="validation"),
]
"""A club as a request field takes it (`club_code`: `7i`, `7 iron`, `I7`, `putter`, ...), kept as its GSPro code."""
