# A home where the straight line misleads (tests/test_base_routes.py, tests/test_base_choice_distance.py):
# after docs/examples/lab6_two_bases.ru, the second Pioneer parked in the bedroom's south-east corner,
# (5.4, 5.6), just behind the wall from the kitchen. The kitchen table's docking pose (8.5, 2.2) is 4.60 m
# from it in a straight line and 5.54 m from P3DX01 at (3.0, 1.5); but P3DX02 must drive out through the
# bedroom door (x 2-3 at y 5) and into the kitchen through its door (y 1.6-2.6 at x 6).
PREFIX home:  <https://w3id.org/cbrs/home#>
PREFIX svc:   <https://w3id.org/cbrs/service#>
DELETE { GRAPH <https://w3id.org/cbrs/graph/map> { svc:P3DX02 home:x ?x ; home:y ?y } }
INSERT { GRAPH <https://w3id.org/cbrs/graph/map> { svc:P3DX02 home:x 5.4 ; home:y 5.6 } }
WHERE  { GRAPH <https://w3id.org/cbrs/graph/map> { svc:P3DX02 home:x ?x ; home:y ?y } }
