# Take the bundled Panda hands off the dual-arm robot's arms (an arm with no gripper has the Panda hand
# meanwhile), so that a file of the lab's own hands can name new ones: a load only adds, and an arm
# naming two grippers is refused.
#   cbrs update --file docs/examples/lab5_unhand.ru
#   cbrs load --graph map docs/examples/lab5_narrow_hands.ttl     (or lab5_short_fingers.ttl, ...)
PREFIX home:  <https://w3id.org/cbrs/home#>
PREFIX world: <https://w3id.org/cbrs/world#>
DELETE WHERE {
  GRAPH <https://w3id.org/cbrs/graph/map> {
    world:CytonDualArm01LeftArm home:hasGripper ?left .
    world:CytonDualArm01RightArm home:hasGripper ?right .
  }
}
