# A seventh-round mistake (docs/tasks.md, "A seventh round"): lab7_where_is_my_pen.ru with the pen's
# class misspelt, home:Pne for home:Pen (two letters swapped), sent to /update as that file is. It must
# be refused, as `cbrs load` and POST /store refuse it: 400 DescriptionShapeError, "home:Pne is declared
# nowhere in the store or in this input (as cbrs:parameterType); did you mean home:Pen?", nothing
# written. Before the fix it was stored (204) and the run found no plan.
PREFIX cbrs: <https://w3id.org/cbrs/core#>
PREFIX home: <https://w3id.org/cbrs/home#>
PREFIX svc:  <https://w3id.org/cbrs/service#>
PREFIX lab7: <https://example.org/lab7#>
INSERT DATA { GRAPH <https://w3id.org/cbrs/graph/requirements> {
  lab7:WhereIsMyPne a cbrs:Requirement ;
    cbrs:requestedBy svc:P3DX01 ; cbrs:deviceName "P3DX01" ; cbrs:serviceName "WhereIsMyPne" ;
    cbrs:hasOWLSModel lab7:WhereIsMyPneModel .
  lab7:WhereIsMyPneModel a cbrs:OWLSModel ;
    cbrs:hasInput lab7:WhereIsMyPnePen ; cbrs:hasOutput lab7:WhereIsMyPnePosition .
  lab7:WhereIsMyPnePen a cbrs:Parameter ; cbrs:parameterName "pen" ; cbrs:parameterType home:Pne .
  lab7:WhereIsMyPnePosition a cbrs:Parameter ; cbrs:parameterName "penPosition" ;
    cbrs:parameterType home:ObjectPosition3D .
} }
