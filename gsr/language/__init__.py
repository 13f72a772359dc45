"""Goal interpretation without an LLM: instruction + scene graph -> PDDL goal (the embedded grounder).

``ground(instruction, graph)`` parses the instruction with a lark grammar over word classes
(instruction.lark), resolves its noun phrases against a lexicon built from the graph, and returns a
``gsr.step.Goal``. Anything not understood or ambiguous raises ``GroundingError`` naming the
unknown words or the candidate objects. See docs/language.md.
"""

from gsr.language.errors import GroundingError
from gsr.language.ground import ground

__all__ = ["GroundingError", "ground"]
