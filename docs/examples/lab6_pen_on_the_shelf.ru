# After ClearPenOffTheTable (docs/examples/lab6_pen_off_the_table.ttl), the lab says in the map where the
# pen now is, on the tidy shelf, in one update (a run builds its home from the map, not from the world
# graph the last run left): the pen's support and pose replaced together, so the map always holds one.
# Then FetchMyPen brings it to the person from the shelf (the base parks at the shelf's docking pose).
# Needs docs/examples/lab6_tidy_shelf.ttl in the ontology and the map.
# The Kinect looks at the table, not at the shelf: hang the fourth round's camera over it first (its
# place is the same), or FetchMyPen is refused before anything moves ("Kinect01 ... cannot see it whole").
#   cbrs --store S load --graph map docs/examples/lab4_trolley_camera_map.ttl
#   cbrs --store S register docs/examples/lab4_trolley_camera.ttl
#   cbrs --store S update --file docs/examples/lab6_pen_on_the_shelf.ru && cbrs --store S run FetchMyPen
PREFIX home:  <https://w3id.org/cbrs/home#>
PREFIX world: <https://w3id.org/cbrs/world#>
PREFIX lab6:  <https://example.org/lab6#>
DELETE { GRAPH <https://w3id.org/cbrs/graph/map> { world:Pen home:isLocatedOn ?on ; home:x ?x ; home:y ?y ; home:yaw ?yaw } }
INSERT { GRAPH <https://w3id.org/cbrs/graph/map> { world:Pen home:isLocatedOn lab6:TidyShelf1 ; home:x 8.62 ; home:y 2.72 ; home:yaw 0.0 } }
WHERE  { GRAPH <https://w3id.org/cbrs/graph/map> { world:Pen home:isLocatedOn ?on ; home:x ?x ; home:y ?y ; home:yaw ?yaw } }
