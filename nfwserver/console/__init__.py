"""The diagnostic console (Textual): live state, outgoing (F1) and incoming (F3) strings, pokes."""
