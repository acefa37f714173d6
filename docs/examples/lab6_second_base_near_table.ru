# The second Pioneer (docs/examples/lab6_two_bases.ru) parked in the living room by the kitchen door,
# nearer the kitchen table than the first (at (3.0, 1.5)), where ceiling camera 1 sees its marker. One
# update (the map is never without its start).
#   cbrs update --file docs/examples/lab6_second_base_near_table.ru
PREFIX home:  <https://w3id.org/cbrs/home#>
PREFIX svc:   <https://w3id.org/cbrs/service#>
DELETE { GRAPH <https://w3id.org/cbrs/graph/map> { svc:P3DX02 home:x ?x ; home:y ?y ; home:yaw ?yaw } }
INSERT { GRAPH <https://w3id.org/cbrs/graph/map> { svc:P3DX02 home:x 5.0 ; home:y 2.1 ; home:yaw 0.0 } }
WHERE  { GRAPH <https://w3id.org/cbrs/graph/map> { svc:P3DX02 home:x ?x ; home:y ?y ; home:yaw ?yaw } }
