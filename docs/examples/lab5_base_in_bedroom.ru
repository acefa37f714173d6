# The lab's mobile base is kept in the bedroom overnight: it starts there, facing west, not in the living
# room. One update (the map is never without its start).
#   cbrs update --file docs/examples/lab5_base_in_bedroom.ru
PREFIX home:  <https://w3id.org/cbrs/home#>
PREFIX svc:   <https://w3id.org/cbrs/service#>
DELETE { GRAPH <https://w3id.org/cbrs/graph/map> { svc:P3DX01 home:x ?x ; home:y ?y ; home:yaw ?yaw } }
INSERT { GRAPH <https://w3id.org/cbrs/graph/map> { svc:P3DX01 home:x 4.0 ; home:y 6.2 ; home:yaw 3.1416 } }
WHERE  { GRAPH <https://w3id.org/cbrs/graph/map> { svc:P3DX01 home:x ?x ; home:y ?y ; home:yaw ?yaw } }
