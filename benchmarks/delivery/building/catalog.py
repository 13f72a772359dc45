"""What a building is furnished with: room kinds, receptacles, object types, roles and their needs.

The catalog is plain data. The generator draws from it (seeded) and the delivery benchmark reads it for
priors ("a stethoscope usually lives in the medical room") and for the parser's lexicon.
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class ReceptacleType:
    """A piece of furniture objects rest on (``on``) or in (``in``); ``size`` is its footprint in cells."""

    category: str
    name: str
    relation: str = "on"
    size: tuple[int, int] = (2, 3)
    closed: bool = False  # a container with a door/drawer the robot must open to see or take contents


@dataclass(frozen=True)
class ObjectType:
    """A movable object kind: display name, colours it comes in, rooms it lives in, grasp difficulty."""

    category: str
    name: str
    colors: tuple[str, ...]
    rooms: tuple[str, ...]
    grasp_success: float = 0.92  # chance one pick attempt succeeds (small/flat things are harder)


@dataclass(frozen=True)
class RoomKind:
    """A kind of room and the receptacles it is furnished with (first ones always, the rest by seed)."""

    kind: str
    name: str
    receptacles: tuple[str, ...]
    always: int = 2


RECEPTACLES: dict[str, ReceptacleType] = {
    r.category: r
    for r in (
        ReceptacleType("dining_table", "dining table", size=(3, 4)),
        ReceptacleType("counter", "counter", size=(2, 5)),
        ReceptacleType("fridge", "fridge", "in", (2, 2), closed=True),
        ReceptacleType("kitchen_cabinet", "kitchen cabinet", "in", (2, 3), closed=True),
        ReceptacleType("sideboard", "sideboard", size=(2, 4)),
        ReceptacleType("coffee_table", "coffee table", size=(2, 3)),
        ReceptacleType("sofa", "sofa", size=(2, 5)),
        ReceptacleType("tv_stand", "tv stand", size=(2, 4)),
        ReceptacleType("bookshelf", "bookshelf", size=(1, 4)),
        ReceptacleType("game_table", "game table", size=(3, 3)),
        ReceptacleType("bench", "bench", size=(2, 4)),
        ReceptacleType("equipment_rack", "equipment rack", size=(2, 3)),
        ReceptacleType("shelf", "shelf", size=(1, 4)),
        ReceptacleType("medicine_cabinet", "medicine cabinet", "in", (1, 3), closed=True),
        ReceptacleType("examination_table", "examination table", size=(2, 4)),
        ReceptacleType("desk", "desk", size=(2, 3)),
        ReceptacleType("reception_desk", "reception desk", size=(2, 5)),
        ReceptacleType("side_table", "side table", size=(2, 2)),
        ReceptacleType("filing_cabinet", "filing cabinet", "in", (2, 2), closed=True),
        ReceptacleType("lab_bench", "lab bench", size=(2, 5)),
        ReceptacleType("storage_cabinet", "storage cabinet", "in", (2, 3), closed=True),
        ReceptacleType("conference_table", "conference table", size=(3, 5)),
        ReceptacleType("reading_table", "reading table", size=(2, 4)),
        ReceptacleType("printer_table", "printer table", size=(2, 3)),
        ReceptacleType("bed", "bed", size=(4, 3)),
        ReceptacleType("nightstand", "nightstand", size=(1, 2)),
        ReceptacleType("wardrobe", "wardrobe", "in", (2, 3), closed=True),
        ReceptacleType("folding_table", "folding table", size=(2, 4)),
        ReceptacleType("washing_machine", "washing machine", "in", (2, 2), closed=True),
    )
}

ROOM_KINDS: dict[str, RoomKind] = {
    k.kind: k
    for k in (
        RoomKind("lobby", "lobby", ("reception_desk", "side_table", "sofa")),
        RoomKind("kitchen", "kitchen", ("dining_table", "counter", "fridge", "kitchen_cabinet"), 3),
        RoomKind("dining_room", "dining room", ("dining_table", "sideboard", "side_table")),
        RoomKind("living_room", "living room", ("coffee_table", "sofa", "tv_stand", "bookshelf")),
        RoomKind("leisure_room", "leisure room", ("game_table", "bookshelf", "sofa", "side_table")),
        RoomKind("gym", "gym", ("bench", "equipment_rack", "shelf")),
        RoomKind("medical_room", "medical room", ("medicine_cabinet", "examination_table", "desk"), 3),
        RoomKind("office", "office", ("desk", "bookshelf", "filing_cabinet", "side_table")),
        RoomKind("laboratory", "laboratory", ("lab_bench", "storage_cabinet", "shelf", "desk"), 3),
        RoomKind("meeting_room", "meeting room", ("conference_table", "sideboard")),
        RoomKind("library", "library", ("bookshelf", "reading_table", "side_table")),
        RoomKind("copy_room", "copy room", ("printer_table", "shelf", "filing_cabinet")),
        RoomKind("bedroom", "bedroom", ("bed", "nightstand", "wardrobe", "desk")),
        RoomKind("laundry_room", "laundry room", ("folding_table", "washing_machine", "shelf")),
        RoomKind("lounge", "lounge", ("coffee_table", "sofa", "bookshelf")),
        RoomKind("corridor", "corridor", (), 0),
    )
}

_ALL = ("red", "blue", "green", "yellow", "white", "black")
_DARK = ("black", "gray", "blue", "brown")
_BRIGHT = ("red", "blue", "green", "yellow", "pink", "purple", "orange")
_EAT = ("kitchen", "dining_room")
_WORK = ("office", "meeting_room", "copy_room", "library")
_HOME = ("bedroom", "living_room", "lounge")

OBJECTS: dict[str, ObjectType] = {
    o.category: o
    for o in (
        ObjectType("water_bottle", "water bottle", _ALL, (*_EAT, "gym", "office")),
        ObjectType("mug", "mug", _ALL, (*_EAT, "office", "lounge")),
        ObjectType("cup", "cup", _ALL, _EAT),
        ObjectType("plate", "plate", ("white", "blue", "green"), _EAT, 0.88),
        ObjectType("bowl", "bowl", ("white", "red", "blue"), _EAT),
        ObjectType("apple", "apple", ("red", "green", "yellow"), (*_EAT, "lounge")),
        ObjectType("banana", "banana", ("yellow",), _EAT),
        ObjectType("orange", "orange", ("orange",), _EAT),
        ObjectType("sandwich", "sandwich", ("brown",), _EAT, 0.9),
        ObjectType("lunch_box", "lunch box", _BRIGHT, (*_EAT, "office")),
        ObjectType("spoon", "spoon", ("gray", "white"), _EAT, 0.8),
        ObjectType("thermos", "thermos", _DARK, (*_EAT, "office", "laboratory")),
        ObjectType("book", "book", _ALL, ("library", "living_room", "leisure_room", "bedroom", "office")),
        ObjectType("notebook", "notebook", _BRIGHT, (*_WORK, "laboratory", "bedroom"), 0.86),
        ObjectType("laptop", "laptop", ("black", "gray", "white"), (*_WORK, "laboratory", "bedroom"), 0.9),
        ObjectType("tablet", "tablet", ("black", "white"), (*_WORK, "living_room", "bedroom"), 0.88),
        ObjectType("phone", "phone", ("black", "white", "blue"), (*_HOME, "office"), 0.88),
        ObjectType("charger", "charger", ("black", "white"), ("office", "bedroom", "copy_room")),
        ObjectType("headphones", "headphones", _DARK, ("office", "bedroom", "gym", "lounge")),
        ObjectType("glasses_case", "glasses case", _DARK, ("office", "bedroom", "library")),
        ObjectType("pen", "pen", ("blue", "black", "red"), (*_WORK, "laboratory"), 0.78),
        ObjectType("stapler", "stapler", ("black", "red"), ("office", "copy_room")),
        ObjectType("folder", "folder", _BRIGHT, ("office", "copy_room", "meeting_room"), 0.85),
        ObjectType("keyboard", "keyboard", ("black", "white"), ("office", "copy_room"), 0.9),
        ObjectType("computer_mouse", "computer mouse", ("black", "white"), ("office", "copy_room")),
        ObjectType(
            "remote_control", "remote control", ("black", "gray"), ("living_room", "leisure_room", "lounge")
        ),
        ObjectType("board_game", "board game", _BRIGHT, ("leisure_room", "living_room")),
        ObjectType("playing_cards", "playing cards", ("red", "blue"), ("leisure_room", "lounge"), 0.82),
        ObjectType("tennis_ball", "tennis ball", ("yellow", "green"), ("gym", "leisure_room")),
        ObjectType("dumbbell", "dumbbell", ("black", "red", "blue"), ("gym",), 0.94),
        ObjectType("yoga_mat", "yoga mat", _BRIGHT, ("gym",)),
        ObjectType("towel", "towel", ("white", "blue", "pink"), ("gym", "laundry_room", "bedroom"), 0.95),
        ObjectType("first_aid_kit", "first aid kit", ("red", "white"), ("medical_room", "gym", "kitchen")),
        ObjectType("thermometer", "thermometer", ("white", "blue"), ("medical_room",), 0.84),
        ObjectType("medicine_bottle", "medicine bottle", ("white", "orange", "brown"), ("medical_room",)),
        ObjectType("pill_box", "pill box", _BRIGHT, ("medical_room", "bedroom"), 0.86),
        ObjectType("bandage_roll", "bandage roll", ("white",), ("medical_room",)),
        ObjectType("stethoscope", "stethoscope", ("black", "blue", "red"), ("medical_room",), 0.88),
        ObjectType("blood_pressure_monitor", "blood pressure monitor", ("white", "gray"), ("medical_room",)),
        ObjectType("test_tube_rack", "test tube rack", ("white", "blue"), ("laboratory",), 0.86),
        ObjectType("beaker", "beaker", ("white",), ("laboratory",), 0.87),
        ObjectType("safety_goggles", "safety goggles", ("white", "yellow"), ("laboratory",)),
        ObjectType("sample_box", "sample box", ("white", "blue", "green"), ("laboratory",)),
        ObjectType("pipette", "pipette", ("white", "blue"), ("laboratory",), 0.8),
        ObjectType(
            "pillow", "pillow", ("white", "blue", "pink", "green"), ("bedroom", "living_room", "lounge"), 0.96
        ),
        ObjectType(
            "blanket",
            "blanket",
            ("blue", "gray", "red", "green"),
            ("bedroom", "living_room", "laundry_room"),
            0.95,
        ),
        ObjectType("alarm_clock", "alarm clock", ("black", "white", "red"), ("bedroom",)),
        ObjectType("teddy_bear", "teddy bear", ("brown", "white"), ("bedroom", "leisure_room")),
        ObjectType("umbrella", "umbrella", _DARK, ("lobby", "office", "bedroom")),
        ObjectType("wallet", "wallet", ("black", "brown"), ("bedroom", "office"), 0.88),
        ObjectType("keys", "keys", ("gray",), ("lobby", "office", "bedroom"), 0.82),
        ObjectType("tissue_box", "tissue box", ("white", "blue"), ("medical_room", "office", "bedroom")),
        ObjectType("plant_pot", "plant pot", ("green", "brown", "white"), ("lobby", "living_room", "office")),
        ObjectType("scissors", "scissors", ("red", "black"), ("office", "copy_room", "laboratory"), 0.8),
        ObjectType("tape_roll", "tape roll", ("white", "gray"), ("copy_room", "office")),
        ObjectType("calculator", "calculator", ("black", "gray"), ("office", "laboratory")),
        ObjectType("detergent_bottle", "detergent bottle", ("blue", "orange", "green"), ("laundry_room",)),
        ObjectType("newspaper", "newspaper", ("gray",), ("lobby", "living_room", "lounge"), 0.85),
    )
}

COLORS: tuple[str, ...] = (
    "red", "blue", "green", "yellow", "white", "black", "gray", "brown", "pink", "purple", "orange",
)  # fmt: skip


@dataclass(frozen=True)
class Role:
    """A person's role: the room kind they work in and what they typically ask for."""

    role: str
    workplace: str
    needs: tuple[str, ...]
    garments: tuple[str, ...] = ("shirt", "sweater", "jacket")
    extra_rooms: tuple[str, ...] = field(default_factory=tuple)


ROLES: dict[str, Role] = {
    r.role: r
    for r in (
        Role(
            "doctor",
            "medical_room",
            ("stethoscope", "thermometer", "blood_pressure_monitor", "tissue_box"),
            ("coat",),
        ),
        Role(
            "nurse",
            "medical_room",
            ("bandage_roll", "medicine_bottle", "pill_box", "first_aid_kit"),
            ("scrubs",),
        ),
        Role("chef", "kitchen", ("bowl", "plate", "spoon", "apple", "orange"), ("apron",)),
        Role("receptionist", "lobby", ("phone", "keys", "newspaper", "umbrella")),
        Role("researcher", "laboratory", ("beaker", "test_tube_rack", "pipette", "sample_box"), ("coat",)),
        Role(
            "lab technician",
            "laboratory",
            ("safety_goggles", "sample_box", "notebook", "calculator"),
            ("coat",),
        ),
        Role("engineer", "office", ("laptop", "charger", "computer_mouse", "keyboard")),
        Role("manager", "office", ("folder", "pen", "stapler", "tablet"), ("suit", "jacket")),
        Role("accountant", "office", ("calculator", "folder", "pen", "glasses_case")),
        Role(
            "fitness coach", "gym", ("dumbbell", "yoga_mat", "towel", "tennis_ball"), ("tracksuit", "t-shirt")
        ),
        Role("librarian", "library", ("book", "notebook", "glasses_case", "tape_roll")),
        Role(
            "student", "bedroom", ("book", "headphones", "board_game", "playing_cards"), ("hoodie", "t-shirt")
        ),
        Role(
            "resident",
            "bedroom",
            ("pillow", "blanket", "alarm_clock", "remote_control"),
            ("sweater", "cardigan"),
        ),
    )
}

#: Things anyone may ask for besides their role's needs.
COMMON_NEEDS: tuple[str, ...] = (
    "water_bottle",
    "mug",
    "cup",
    "sandwich",
    "banana",
    "lunch_box",
    "thermos",
    "wallet",
)


def room_kind(kind: str) -> RoomKind:
    """The room kind ``kind``; KeyError naming the known ones."""
    try:
        return ROOM_KINDS[kind]
    except KeyError:
        raise KeyError(f"unknown room kind {kind!r} (known: {', '.join(sorted(ROOM_KINDS))})") from None
