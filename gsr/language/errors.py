"""The grounding error: an instruction that is not understood or does not pick out one goal."""

from __future__ import annotations

from gsr.errors import GSRError


class GroundingError(GSRError):
    """The instruction could not be grounded; names the unknown words or the candidate objects.

    ``unknown_words``: words outside the lexicon. ``candidates``: the objects an ambiguous
    reference could denote (or that a reference was checked against). ``phrase``: the words of the
    reference that failed, when there is one. ``suggestions``: for each unknown word, the known
    words closest to it (gsr.language.fallback).
    """

    def __init__(
        self,
        message: str,
        *,
        unknown_words: tuple[str, ...] = (),
        candidates: tuple[str, ...] = (),
        phrase: str | None = None,
    ) -> None:
        self.message = message
        self.unknown_words = tuple(unknown_words)
        self.candidates = tuple(candidates)
        self.phrase = phrase
        self.suggestions: dict[str, tuple[str, ...]] = {}  # unknown word -> the closest known words
        super().__init__(message)
