# The cup moved from (7.45, 3.32), where the front mat (lab6_front_mat.ttl) lies, to the kitchen table's
# front edge, 0.51 m from the left arm's mount and 0.69 m from the right's, where the Kinect sees it.
#   cbrs --store S update --file docs/examples/lab6_cup_to_the_front.ru
PREFIX home: <https://w3id.org/cbrs/home#>
PREFIX world: <https://w3id.org/cbrs/world#>
DELETE { GRAPH <https://w3id.org/cbrs/graph/map> { world:Cup home:x ?x ; home:y ?y } }
INSERT { GRAPH <https://w3id.org/cbrs/graph/map> { world:Cup home:x 7.45 ; home:y 3.05 } }
WHERE { GRAPH <https://w3id.org/cbrs/graph/map> { world:Cup home:x ?x ; home:y ?y } }
