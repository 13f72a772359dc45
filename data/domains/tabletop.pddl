; The GSR tabletop manipulation domain, shared by every suite (GSR-Bench, LIBERO, RLBench-style).
;
; One arm. Objects are typed by their scene-graph category (see gsr/categories.py); what an
; object affords is given by static facts generated from the category registry: (movable x),
; (container x), (supporter x), (openable x), (switchable x), (pressable x), (pushable x),
; (stackable x), (counted x). The GSR-Bench validity rules are preconditions here:
;   * an object with something on top of it cannot be picked or opened;
;   * an object inside a container that has something on top cannot be taken out;
;   * a cube resting on anything but a base surface (the table) cannot be picked (GSR-Bench counts it
;     among what covers its own support);
;   * a closed openable container must be open to put something in or take it out;
;   * a drawer is reachable (open, close, put in, take out) only while the drawers above it are closed;
;   * a container with something on top receives nothing, in or on; so does any (receives_uncovered)
;     surface (every non-table support of a GSR-Bench scene);
;   * no container goes inside or onto a container;
;   * nothing is placed on a cube or a mug (they are not supporters), nor on a (full) table;
;   * a container takes a cube only while it holds fewer than 10 cubes.
; Cube capacity is counted without numeric fluents: (cube_count ?c ?n) over the count constants
; n0..n10 with the static successor relation (next ?n ?m), updated by conditional effects.
; See docs/tabletop-domain.md.

(define (domain tabletop)
  (:requirements :strips :typing :negative-preconditions :equality
                 :disjunctive-preconditions :existential-preconditions
                 :universal-preconditions :conditional-effects)

  (:types
    thing color count - object
    furniture appliance part receptacle tableware cookware food toy book bottle - thing
    table floor cabinet shelf rack - furniture
    microwave stove lamp tap - appliance
    drawer cabinet_top cabinet_interior compartment burner door button switch region - part
    box basket tray caddy - receptacle
    lidded_box - box
    plate bowl mug cup ramekin - tableware
    pot pan - cookware
    moka_pot - pot
    cube block - toy
    wine_bottle - bottle
    milk popcorn ketchup alphabet_soup cream_cheese butter bbq_sauce tomato_sauce orange_juice
    salad_dressing chocolate_pudding macaroni_and_cheese cookie_box - food
  )

  (:constants
    red blue yellow green black white orange purple pink brown grey gold silver cyan - color
    n0 n1 n2 n3 n4 n5 n6 n7 n8 n9 n10 - count
  )

  (:predicates
    ; static: affordances and structure, from the category registry and the scene graph
    (movable ?x - thing)
    (container ?x - thing)
    (supporter ?x - thing)
    (openable ?x - thing)
    (switchable ?x - thing)
    (pressable ?x - thing)
    (pushable ?x - thing)
    (stackable ?x - thing)
    (counted ?x - thing)
    (base_surface ?x - thing)
    (receives_uncovered ?x - thing)
    (full ?x - thing)
    (part_of ?p - thing ?o - thing)
    (above ?upper - thing ?lower - thing)
    (has_color ?x - thing ?c - color)
    (next ?n - count ?m - count)
    ; fluents
    (on ?x - thing ?y - thing)
    (in ?x - thing ?y - thing)
    (open ?x - thing)
    (turned_on ?x - thing)
    (holding ?x - thing)
    (hand_empty)
    (cube_count ?c - thing ?n - count)
  )

  ; Take ?o from the thing it is on or in.
  (:action pick
    :parameters (?o - thing ?from - thing)
    :precondition (and
      (movable ?o)
      (hand_empty)
      (or (on ?o ?from) (in ?o ?from))
      ; nothing may be on top of the object
      (not (exists (?z - thing) (on ?z ?o)))
      ; taking out of a closed container is impossible
      (imply (and (in ?o ?from) (openable ?from)) (open ?from))
      ; ... and so is taking out of a container with something on top
      (imply (in ?o ?from) (not (exists (?y - thing) (on ?y ?from))))
      ; a cube on anything but a base surface is stuck
      (imply (and (counted ?o) (on ?o ?from)) (base_surface ?from))
      ; a drawer is reachable only while the drawers above it are closed
      (imply (in ?o ?from) (not (exists (?d - thing) (and (above ?d ?from) (open ?d)))))
      ; a supporter inside a closed container is out of reach
      (not (exists (?c - thing) (and (in ?from ?c) (openable ?c) (not (open ?c))))))
    :effect (and
      (holding ?o)
      (not (hand_empty))
      (not (on ?o ?from))
      (not (in ?o ?from))
      (forall (?n - count ?m - count)
        (when (and (in ?o ?from) (counted ?o) (cube_count ?from ?m) (next ?n ?m))
          (and (not (cube_count ?from ?m)) (cube_count ?from ?n))))))

  ; Put the held object on a supporting surface.
  (:action place_on
    :parameters (?o - thing ?s - thing)
    :precondition (and
      (holding ?o)
      (supporter ?s)
      (not (= ?o ?s))
      (not (on ?o ?s))
      (not (full ?s))
      ; no container onto a container
      (not (and (container ?o) (container ?s)))
      ; a covered container or receives_uncovered surface takes nothing
      (imply (or (container ?s) (receives_uncovered ?s)) (not (exists (?y - thing) (on ?y ?s))))
      ; GSR-Bench: a closed lidded box takes nothing, not even on its lid
      (imply (and (receives_uncovered ?s) (openable ?s)) (open ?s))
      (not (exists (?c - thing) (and (in ?s ?c) (openable ?c) (not (open ?c))))))
    :effect (and
      (not (holding ?o))
      (hand_empty)
      (on ?o ?s)))

  ; Put the held object into a container.
  (:action place_in
    :parameters (?o - thing ?c - thing)
    :precondition (and
      (holding ?o)
      (container ?c)
      (not (= ?o ?c))
      (not (in ?o ?c))
      ; no container inside a container
      (not (container ?o))
      ; a container with something on top takes nothing
      (not (exists (?y - thing) (on ?y ?c)))
      ; a closed container must be opened first
      (imply (openable ?c) (open ?c))
      ; a drawer is reachable only while the drawers above it are closed
      (not (exists (?d - thing) (and (above ?d ?c) (open ?d))))
      ; a container takes a cube only while it holds fewer than 10 cubes
      (imply (counted ?o) (not (cube_count ?c n10))))
    :effect (and
      (not (holding ?o))
      (hand_empty)
      (in ?o ?c)
      (forall (?n - count ?m - count)
        (when (and (counted ?o) (cube_count ?c ?n) (next ?n ?m))
          (and (not (cube_count ?c ?n)) (cube_count ?c ?m))))))

  (:action open
    :parameters (?x - thing)
    :precondition (and
      (openable ?x)
      (not (open ?x))
      (hand_empty)
      ; a lid with something on it cannot be opened
      (not (exists (?z - thing) (on ?z ?x)))
      (not (exists (?d - thing) (and (above ?d ?x) (open ?d)))))
    :effect (open ?x))

  (:action close
    :parameters (?x - thing)
    :precondition (and
      (openable ?x)
      (open ?x)
      (hand_empty)
      (not (exists (?d - thing) (and (above ?d ?x) (open ?d)))))
    :effect (not (open ?x)))

  (:action turn_on
    :parameters (?x - thing)
    :precondition (and
      (switchable ?x)
      (not (turned_on ?x))
      (hand_empty))
    :effect (turned_on ?x))

  (:action turn_off
    :parameters (?x - thing)
    :precondition (and
      (switchable ?x)
      (turned_on ?x)
      (hand_empty))
    :effect (not (turned_on ?x)))

  ; Press a button or switch: it toggles itself and the switchable thing it belongs to.
  (:action press
    :parameters (?x - thing)
    :precondition (and
      (pressable ?x)
      (hand_empty))
    :effect (and
      (when (turned_on ?x) (not (turned_on ?x)))
      (when (not (turned_on ?x)) (turned_on ?x))
      (forall (?o - thing)
        (and
          (when (and (part_of ?x ?o) (switchable ?o) (turned_on ?o)) (not (turned_on ?o)))
          (when (and (part_of ?x ?o) (switchable ?o) (not (turned_on ?o))) (turned_on ?o))))))

  ; Slide an object along a surface: between a surface and its regions, or between two regions of one surface.
  (:action push
    :parameters (?o - thing ?from - thing ?to - thing)
    :precondition (and
      (pushable ?o)
      (hand_empty)
      (on ?o ?from)
      (supporter ?to)
      (not (= ?from ?to))
      (not (= ?o ?to))
      (or (part_of ?to ?from)
          (part_of ?from ?to)
          (exists (?t - thing) (and (part_of ?from ?t) (part_of ?to ?t)))))
    :effect (and
      (not (on ?o ?from))
      (on ?o ?to)))

  ; Stack the held stackable object (block, cup) on a clear stackable one.
  (:action stack
    :parameters (?o - thing ?b - thing)
    :precondition (and
      (holding ?o)
      (stackable ?o)
      (stackable ?b)
      (not (= ?o ?b))
      (not (exists (?z - thing) (on ?z ?b)))
      (not (exists (?c - thing) (and (in ?b ?c) (openable ?c) (not (open ?c))))))
    :effect (and
      (not (holding ?o))
      (hand_empty)
      (on ?o ?b)))
)
