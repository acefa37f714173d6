# The living room at night, for the ninth round's FetchMyBookIfDark (docs/tasks.md "A ninth round"): the
# map states the room's light level, 12 lx (a room lit only by a street lamp through the window), in place
# of any level it stated before. The simulated sensor board reads the level the map states for the room
# its effective area names, else its class's (home:Room: 300 lx, lit by day; docs/execution.md, "A sensed precondition in the simulated home"),
# so the run's precondition (home:LivingRoom, home:hasStatus, lab9:Dark) is read holding, 12 lx below
# lab9:Dark's 50 lx (docs/examples/lab9_dark.ttl). On a store set up as lab9_fetch_my_book_if_dark.ttl says:
#   cbrs --store S update --file docs/examples/lab9_living_room_at_night.ru
#   cbrs --store S run FetchMyBookIfDark --seed 0
PREFIX home:  <https://w3id.org/cbrs/home#>
PREFIX world: <https://w3id.org/cbrs/world#>

DELETE { GRAPH graph:map { world:LivingRoom home:lightLevel ?before } }
INSERT { GRAPH graph:map { world:LivingRoom home:lightLevel 12.0 } }
WHERE { OPTIONAL { GRAPH graph:map { world:LivingRoom home:lightLevel ?before } } }
