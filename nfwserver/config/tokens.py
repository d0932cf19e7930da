"""The web dashboard's control token: what is refused as too weak, a fresh strong one, and the comparison.

A token is refused when a stranger could guess it without trying many: the configuration template's
example (``change-me-0123``), anything with white space (eight spaces, a pasted line break), fewer than
:data:`MIN_TOKEN_CHARS` characters, fewer than :data:`MIN_DISTINCT_CHARS` different characters
(``aaaaaaaa``, ``abababab``), a straight run of neighbouring characters (``12345678``, ``abcdefgh``,
``87654321``) and a few passwords every guesser tries first.  :func:`new_token` makes one of 24
characters from :mod:`secrets` (144 bits).
"""

from __future__ import annotations

# hashlib, hmac and secrets are imported where they are used: they load OpenSSL's libcrypto (about 3.5 MiB and a
# few milliseconds), which every command reading the configuration (``passes --sat``) would pay for nothing.

__all__ = ["MIN_TOKEN_CHARS", "TEMPLATE_TOKEN", "new_token", "token_matches", "weak_token_reason"]

MIN_TOKEN_CHARS = 8
MIN_DISTINCT_CHARS = 5
TEMPLATE_TOKEN = "change-me-0123"  #: the example the template shows; never accepted
_GUESSED_FIRST = frozenset({"password", "passw0rd", "password1", "qwertyuiop", "qwertyui", "letmein1",
                            "iloveyou", "changeme", "change-me", "trustno1", "admin123", "administrator",
                            "nfwserver", "nfwserver1", "secret12", "12345678a"})


def weak_token_reason(token: str) -> str | None:
    """Why ``token`` is refused as a control token (a phrase), or None when it is acceptable."""
    if any(ch.isspace() for ch in token):
        return "must not contain spaces or other white space"
    if len(token) < MIN_TOKEN_CHARS:
        return f"must be at least {MIN_TOKEN_CHARS} characters"
    if token == TEMPLATE_TOKEN or token.lower() in _GUESSED_FIRST:
        return "is the template's example or a common password"
    if len(set(token)) < MIN_DISTINCT_CHARS:
        return f"must have at least {MIN_DISTINCT_CHARS} different characters"
    steps = {ord(b) - ord(a) for a, b in zip(token, token[1:])}
    if steps in ({1}, {-1}):
        return "is a run of neighbouring characters"
    return None


def new_token() -> str:
    """A fresh random token of 24 URL-safe characters (never weak by :func:`weak_token_reason`)."""
    import secrets

    while True:
        token = secrets.token_urlsafe(18)
        if weak_token_reason(token) is None:
            return token


def token_matches(given: str, expected: str) -> bool:
    """Whether ``given`` is ``expected``, in a time that depends on neither (their SHA-256 digests are
    compared with :func:`hmac.compare_digest`, so not even the length leaks)."""
    import hashlib
    import hmac

    digest = hashlib.sha256
    return hmac.compare_digest(digest(given.encode("utf-8", "surrogatepass")).digest(),
                               digest(expected.encode("utf-8", "surrogatepass")).digest())
