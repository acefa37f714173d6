// The lab's web-side program (the ninth round, docs/tasks.md "A ninth round"): roslibjs under Node starts
// FetchMyBook on a running `cbrs serve` as the /cbrs/run_task action, prints each step's feedback, stops
// the run once the notebook is on the base's platform (a cancel, as the lab's "stop" button does), and then
// asks the store over /cbrs/query where the robots believe the notebook is. Its newcomer's mistakes come
// first: the goal sent before the update token, and the task's name misspelt (FetchMyBok).
// Needs docs/examples/lab9_book_on_box.ttl in the ontology and the map and lab9_fetch_my_book.ttl in the
// requirements of the server's store; roslib installed beside it (npm install roslib):
//   CBRS_UPDATE_TOKEN=secret cbrs --store S serve
//   CBRS_UPDATE_TOKEN=secret node lab9_run_and_stop.mjs [ws://127.0.0.1:9090] [seed]
// It prints one line of JSON: each attempt's outcome, the steps' feedback, the run's status and the beliefs.
// Every wait is bounded: it gives up (exit status 2) after 180 s.

import { Action, Ros, Service } from "roslib";

const url = process.argv[2] ?? "ws://127.0.0.1:9090";
const seed = Number(process.argv[3] ?? 0);
const token = process.env.CBRS_UPDATE_TOKEN ?? "";
setTimeout(() => {
  console.error("lab9_run_and_stop.mjs: gave up after 180 s");
  process.exit(2);
}, 180000).unref();

const ros = await new Promise((resolve, reject) => {
  const connection = new Ros({ url });
  connection.on("connection", () => resolve(connection));
  connection.on("error", (error) => reject(new Error(`cannot reach ${url}: ${error?.message ?? error}`)));
});
const runTask = new Action({ ros, name: "/cbrs/run_task", actionType: "cbrs/action/RunTask" });

// One goal; stopAfter(step) says when to cancel it. Resolves with what the callbacks said.
function run(goal, stopAfter = () => false) {
  const feedback = [];
  return new Promise((resolve) => {
    let id = null;
    let stopped = false;
    id = runTask.sendGoal(
      goal,
      (result) => resolve({ feedback, result }),
      (step) => {
        feedback.push(`${step.step} ${String(step.component).split("#").pop()} ${step.status}`);
        if (!stopped && stopAfter(step)) {
          stopped = true;
          runTask.cancelGoal(id);
        }
      },
      (error) => resolve({ feedback, error: String(error) }),
    );
  });
}

const found = {};
found.before_token = await run({ task: "FetchMyBook", seed }); // mistake: no token yet
ros.authenticate(token, "", "", "", 0, "", 0); // cbrs reads the update token from the mac field
found.misspelt = await run({ task: "FetchMyBok", seed }); // mistake: the task's name
const loaded = (step) => step.status === "succeeded" && String(step.component).endsWith("HandOverOntoPlatform_CytonDualArm01");
const stopped = await run({ task: "FetchMyBook", seed }, loaded);
// roslibjs hands a goal that ended other than SUCCEEDED to the failed callback, the run's JSON in its words
const cancelled = "GoalError: Action was canceled: ";
const ended = stopped.result ?? (stopped.error?.startsWith(cancelled) ? JSON.parse(stopped.error.slice(cancelled.length)) : null);
found.run = {
  feedback: stopped.feedback,
  error: ended === null ? stopped.error : undefined,
  status: ended?.status ?? null,
  execution: ended?.result?.execution?.reason ?? null,
  sim_seconds: ended?.result?.sim_seconds ?? null,
  goals: ended?.result?.goals ?? null,
};

const query = new Service({ ros, name: "/cbrs/query", serviceType: "cbrs/Query" });
const beliefs = await new Promise((resolve) =>
  query.callService(
    {
      query:
        "PREFIX lab9: <https://example.org/lab9#> SELECT ?relation ?other WHERE { GRAPH graph:world { lab9:Notebook1 ?relation ?other } }",
    },
    (answer) => resolve(answer.result.results.bindings.map((row) => `${row.relation.value} ${row.other.value}`)),
    (error) => resolve([`query failed: ${error}`]),
  ),
);
found.notebook_believed = beliefs;
console.log(JSON.stringify(found));
ros.close();
process.exit(0);
