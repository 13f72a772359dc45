"""What a delivery instruction says: the object and person references (also the parser's output)."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict


class ObjectRef(BaseModel):
    """The object to fetch: category plus whatever the instruction adds (colour, receptacle, room)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    category: str
    color: str | None = None
    receptacle: str | None = None  # receptacle category ("dining_table")
    room: str | None = None  # room id


class PersonRef(BaseModel):
    """The recipient: a name and/or a description, and optionally the room they are said to be in."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    name: str | None = None
    role: str | None = None
    gender: str | None = None
    garment: str | None = None
    color: str | None = None
    hair: str | None = None
    glasses: bool | None = None
    room: str | None = None


class Reference(BaseModel):
    """A parsed (or ground-truth) delivery instruction."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    object: ObjectRef
    person: PersonRef
