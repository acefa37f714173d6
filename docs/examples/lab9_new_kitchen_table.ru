# The lab's new kitchen table in place of the bundled one (the ninth round, docs/tasks.md "A ninth round"):
# 1.8 m long (x 7.0 .. 8.8, 30 cm longer to the east), as high, the same docking pose. One update: the old
# table's statements deleted, the new table inserted, and everything that stood on the old table (the cup,
# the pen, the water dispenser, and whatever a lab put there) re-pointed to the new one, so that the map is
# never without a support (lab9_mistake_new_table.ru forgets that part). Then the bundled tasks run on it:
#   cbrs --store S update --file docs/examples/lab9_new_kitchen_table.ru
#   cbrs --store S run FetchMyPen --seed 0 && cbrs --store S run RobotArmServeACup --seed 0
PREFIX home:  <https://w3id.org/cbrs/home#>
PREFIX world: <https://w3id.org/cbrs/world#>
PREFIX lab9:  <https://example.org/lab9#>
PREFIX rdfs:  <http://www.w3.org/2000/01/rdf-schema#>
DELETE { GRAPH <https://w3id.org/cbrs/graph/map> { ?thing home:isLocatedOn world:KitchenTable } }
INSERT { GRAPH <https://w3id.org/cbrs/graph/map> { ?thing home:isLocatedOn lab9:KitchenTable2 } }
WHERE  { GRAPH <https://w3id.org/cbrs/graph/map> { ?thing home:isLocatedOn world:KitchenTable } } ;
DELETE WHERE { GRAPH <https://w3id.org/cbrs/graph/map> { world:KitchenTable ?p ?o } } ;
INSERT DATA {
  GRAPH <https://w3id.org/cbrs/graph/map> {
    lab9:KitchenTable2 a home:Table ; rdfs:label "the lab's new kitchen table, 1.8 m long"@en ;
        home:isLocated world:Kitchen ;
        home:minX 7.0 ; home:maxX 8.8 ; home:minY 3.0 ; home:maxY 4.5 ; home:minZ 0.0 ; home:maxZ 0.75 ;
        home:dockingPose world:KitchenTableDock .
  }
}
