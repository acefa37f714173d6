# A lab's dual-arm robot stands 20 cm further west along the kitchen table's south edge than the bundled
# one: the torso, both arms' mounts and the Kinect on its mast move with it (the Kinect turned back
# towards the table's middle), and the table's docking pose comes 20 cm west and 5 cm south, so the
# right arm still reaches the platform. One update, so the map is never without a position.
#   cbrs update --file docs/examples/lab5_robot_west.ru
PREFIX home:  <https://w3id.org/cbrs/home#>
PREFIX svc:   <https://w3id.org/cbrs/service#>
PREFIX world: <https://w3id.org/cbrs/world#>
DELETE {
  GRAPH <https://w3id.org/cbrs/graph/map> {
    svc:CytonDualArm01 home:minX ?tminx ; home:maxX ?tmaxx .
    world:CytonDualArm01LeftArm home:x ?lx .
    world:CytonDualArm01RightArm home:x ?rx .
    svc:Kinect01 home:x ?kx ; home:yaw ?kyaw ; home:pitch ?kpitch .
    world:KitchenTableDock home:x ?dx ; home:y ?dy .
  }
}
INSERT {
  GRAPH <https://w3id.org/cbrs/graph/map> {
    svc:CytonDualArm01 home:minX 7.30 ; home:maxX 7.80 .
    world:CytonDualArm01LeftArm home:x 7.37 .
    world:CytonDualArm01RightArm home:x 7.73 .
    svc:Kinect01 home:x 7.55 ; home:yaw 1.3633 ; home:pitch -0.6248 .
    world:KitchenTableDock home:x 8.30 ; home:y 2.15 .
  }
}
WHERE {
  GRAPH <https://w3id.org/cbrs/graph/map> {
    svc:CytonDualArm01 home:minX ?tminx ; home:maxX ?tmaxx .
    world:CytonDualArm01LeftArm home:x ?lx .
    world:CytonDualArm01RightArm home:x ?rx .
    svc:Kinect01 home:x ?kx ; home:yaw ?kyaw ; home:pitch ?kpitch .
    world:KitchenTableDock home:x ?dx ; home:y ?dy .
  }
}
