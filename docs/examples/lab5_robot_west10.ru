# A lab's dual-arm robot stands 10 cm further west along the kitchen table's south edge than the bundled
# one: the torso, both arms' mounts and the Kinect on its mast move with it (the Kinect turned back
# towards the table's middle), and the table's docking pose comes 10 cm west, so the
# right arm still reaches the platform. One update, so the map is never without a position.
#   cbrs update --file docs/examples/lab5_robot_west10.ru
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
    svc:CytonDualArm01 home:minX 7.40 ; home:maxX 7.90 .
    world:CytonDualArm01LeftArm home:x 7.47 .
    world:CytonDualArm01RightArm home:x 7.83 .
    svc:Kinect01 home:x 7.65 ; home:yaw 1.4659 ; home:pitch -0.6326 .
    world:KitchenTableDock home:x 8.40 ; home:y 2.20 .
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
