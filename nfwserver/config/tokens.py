"""The web dashboard's control token: what is refused as too weak, a fresh strong one, and the comparison.

A token is refused when a stranger could guess it without trying many.  The strength is estimated by
``zxcvbn`` (PyPI, the Python port of Dropbox's estimator): it finds keyboard walks (``qwerty123``,
``1q2w3e4r5t``, ``asdfghjkl``), sequences (``abcd1234``, ``01234567890``), repeats (``abababab``),
dictionary words, names and common passwords, leet-speak and dates, and estimates the guesses an attacker
needs.  A token needs zxcvbn's score :data:`MIN_SCORE` (3: more than 10^8 guesses; the station's own words,
:data:`STATION_WORDS`, count as known to the attacker).  Besides: white space anywhere (a pasted line break)
and fewer than :data:`MIN_TOKEN_CHARS` characters are refused outright, and so is the configuration
template's example (``change-me-0123``).  :func:`new_token` makes one of 24 characters from :mod:`secrets`
(144 bits).

The one check every path uses: the configuration table's entry for ``[web] token``
(:mod:`nfwserver.config.table`) names :func:`weak_token_reason` as its check, so ``config set`` refuses a
weak token, a file that already holds one loads with one warning and web control off
(:mod:`nfwserver.config.loader`), and the web face checks it again at every request
(:mod:`nfwserver.web.control`).
"""

from __future__ import annotations

from functools import lru_cache

# hashlib, hmac, secrets and zxcvbn are imported where they are used: the first three load OpenSSL's libcrypto
# (about 3.5 MiB and a few milliseconds) and zxcvbn its word lists (about 20 ms), which every command reading a
# configuration without a token would pay for nothing.

__all__ = ["MIN_SCORE", "MIN_TOKEN_CHARS", "STATION_WORDS", "TEMPLATE_TOKEN", "new_token", "token_matches",
           "weak_token_reason"]

MIN_TOKEN_CHARS = 8
MIN_SCORE = 3  #: zxcvbn's score (0..4) a token needs: 3 is "more than 10^8 guesses"
TEMPLATE_TOKEN = "change-me-0123"  #: the example the template shows; never accepted
#: words an attacker of this station tries first (zxcvbn's ``user_inputs``)
STATION_WORDS = ("nfwserver", "nova", "novaforwindows", "station", "satellite", "orbitdrv", "hamlib", "rotor",
                 "token", "change-me", "changeme", "dashboard")


@lru_cache(maxsize=16)  # the web face asks at every request; a token changes rarely
def weak_token_reason(token: str) -> str | None:
    """Why ``token`` is refused as a control token (a phrase: "is a keyboard walk ..."), or None."""
    if any(ch.isspace() for ch in token):
        return "must not contain spaces or other white space"
    if len(token) < MIN_TOKEN_CHARS:
        return f"must be at least {MIN_TOKEN_CHARS} characters"
    if token == TEMPLATE_TOKEN:
        return "is the template's example"
    from zxcvbn import zxcvbn

    estimate = zxcvbn(token[:100], user_inputs=list(STATION_WORDS))  # zxcvbn's time grows with the length
    if int(estimate["score"]) >= MIN_SCORE:
        return None
    feedback = estimate.get("feedback") or {}
    warning = str(feedback.get("warning") or "").rstrip(".") or _pattern_phrase(estimate)
    guesses = float(estimate["guesses_log10"])
    return (f"is too easy to guess ({warning[0].lower() + warning[1:]}; about 10^{guesses:.0f} guesses, "
            f"strength {estimate['score']} of 4, at least {MIN_SCORE} needed)")


_PATTERNS = {"dictionary": "dictionary words or names", "spatial": "keyboard patterns", "sequence": "sequences",
             "repeat": "repeats", "date": "dates", "regex": "years"}


def _pattern_phrase(estimate: dict[str, object]) -> str:
    """What zxcvbn found, when it gives no warning of its own."""
    sequence = estimate.get("sequence")
    found = {_PATTERNS.get(str(part.get("pattern")), "") for part in sequence if isinstance(part, dict)} \
        if isinstance(sequence, list) else set()
    found.discard("")
    return "made of " + " and ".join(sorted(found)) if found else "too short for a random token"


def new_token() -> str:
    """A fresh random token of 24 URL-safe characters (never weak by :func:`weak_token_reason`), never starting
    with ``-``, so the command line offered with it (``nfwserver config set web.token TOKEN``) takes it."""
    import secrets

    while True:
        token = secrets.token_urlsafe(18)
        if not token.startswith("-") and weak_token_reason(token) is None:
            return token


def token_matches(given: str, expected: str) -> bool:
    """Whether ``given`` is ``expected``, in a time that depends on neither (their SHA-256 digests are
    compared with :func:`hmac.compare_digest`, so not even the length leaks)."""
    import hashlib
    import hmac

    digest = hashlib.sha256
    return hmac.compare_digest(digest(given.encode("utf-8", "surrogatepass")).digest(),
                               digest(expected.encode("utf-8", "surrogatepass")).digest())
