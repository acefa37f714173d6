# A seventh-round trial (docs/tasks.md, "A seventh round"): an information task, asked only over HTTP.
# "Where is my pen?": a requirement whose only goal is an output, the pen's position as the Kinect
# sees it (home:ObjectPosition3D); nothing moves. It is a SPARQL update, sent to the /update of a
# running `cbrs serve` with the update token (no Turtle file on disk is loaded, no `cbrs load`):
#
#   curl -H 'Authorization: Bearer secret' -H 'Content-Type: application/sparql-update' \
#        --data-binary @docs/examples/lab7_where_is_my_pen.ru http://127.0.0.1:8080/update
#   curl -H 'Authorization: Bearer secret' -H 'Accept: application/json' \
#        --data-urlencode task=WhereIsMyPen http://127.0.0.1:8080/tasks.json     # 202, Location: /tasks/run-1.json
#   curl http://127.0.0.1:8080/tasks/run-1.json                                  # its answers: objectPosition
#
# Every node is named (lab7:WhereIsMyPenModel ...): /update refuses blank nodes ([ ... ], as the
# Turtle of docs/tasks.md writes a task) with BlankNodeInsertError, so that what it stores can be read
# and deleted by name. The requirement goes into the requirements graph; the same INSERT DATA without the GRAPH block
# writes it into the default graph (a newcomer's mistake), where it is checked as here and found as a task.
PREFIX cbrs: <https://w3id.org/cbrs/core#>
PREFIX home: <https://w3id.org/cbrs/home#>
PREFIX svc:  <https://w3id.org/cbrs/service#>
PREFIX lab7: <https://example.org/lab7#>
INSERT DATA { GRAPH <https://w3id.org/cbrs/graph/requirements> {
  lab7:WhereIsMyPen a cbrs:Requirement ;
    cbrs:requestedBy svc:P3DX01 ; cbrs:deviceName "P3DX01" ; cbrs:serviceName "WhereIsMyPen" ;
    cbrs:hasOWLSModel lab7:WhereIsMyPenModel .
  lab7:WhereIsMyPenModel a cbrs:OWLSModel ;
    cbrs:hasInput lab7:WhereIsMyPenPen ; cbrs:hasOutput lab7:WhereIsMyPenPosition .
  lab7:WhereIsMyPenPen a cbrs:Parameter ; cbrs:parameterName "pen" ; cbrs:parameterType home:Pen .
  lab7:WhereIsMyPenPosition a cbrs:Parameter ; cbrs:parameterName "penPosition" ;
    cbrs:parameterType home:ObjectPosition3D .
} }
