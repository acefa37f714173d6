# Someone moved the full flask between two runs: the magenta flask of lab11_two_flasks.ttl from (7.62, 3.12)
# to (7.55, 3.10), west of where it stood, said by one update that deletes the old position and inserts the new
# (docs/tasks.md, "Add an object"); then FetchMyFullFlask again (docs/tasks.md, "An eleventh round"):
#   cbrs --store S update --file docs/examples/lab11_full_flask_moved.ru
#   cbrs --store S run FetchMyFullFlask --seed 0
PREFIX home:  <https://w3id.org/cbrs/home#>
PREFIX lab11: <https://example.org/lab11#>
DELETE { GRAPH graph:map { lab11:Flask1 home:x ?x ; home:y ?y } }
INSERT { GRAPH graph:map { lab11:Flask1 home:x 7.55 ; home:y 3.10 } }
WHERE { GRAPH graph:map { lab11:Flask1 home:x ?x ; home:y ?y } }
