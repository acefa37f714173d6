// roslibjs, unchanged, against a running cbrs server: the knowledge base's own services, as a web page
// uses them. tests/test_serve_clients.py runs it and compares what it prints (one line of JSON) with
// the library's own answers.
//
//     node tests/js/cbrs_services.mjs PORT
//
// Every wait is bounded; the script gives up (exit status 2) after 150 s in all.

import { Ros, Service, Topic } from "roslib";
import { bounded } from "./bounded.mjs";

const WAIT = 10000;
const url = `ws://127.0.0.1:${Number(process.argv[2])}`;
const QUERY = "SELECT ?d WHERE { ?s cbrs:deviceName ?d } ORDER BY ?d LIMIT 3";

setTimeout(() => {
  console.error("cbrs_services.mjs: gave up after 150 s");
  process.exit(2);
}, 150000).unref();


// A failed call resolves to {failed: <the error text>}.
function call(ros, name, type, request, ms = WAIT) {
  const service = new Service({ ros, name, serviceType: type });
  return bounded(`call ${name}`, ms, (resolve) =>
    service.callService(request, resolve, (error) => resolve({ failed: String(error) })),
  );
}

const ros = await bounded("connect", WAIT, (resolve, reject) => {
  const connection = new Ros({ url });
  connection.on("connection", () => resolve(connection));
  connection.on("error", (error) => reject(new Error(`connect: ${error?.message ?? error}`)));
});

const found = {};
found.topics = await bounded("topics", WAIT, (resolve, reject) =>
  ros.getTopics((result) => resolve([...result.topics].sort()), reject),
);
const progress = [];
new Topic({ ros, name: "/cbrs/task_progress", messageType: "cbrs/TaskProgress" }).subscribe((message) =>
  progress.push(message),
);
await new Promise((resolve) => setTimeout(resolve, 300));

const answer = await call(ros, "/cbrs/query", "cbrs/Query", { query: QUERY });
found.devices = answer.result.results.bindings.map((row) => row.d.value);
const ranking = await call(ros, "/cbrs/match", "cbrs/Match", { requirement: "RobotSelfPosition", top: 1 });
found.best = ranking.candidates[0].advertisement;
found.refused = (await call(ros, "/cbrs/query", "cbrs/Query", {})).failed;

found.anonymous = (await call(ros, "/cbrs/run_task", "cbrs/RunTask", { task: "RobotArmServeACup" })).failed;
ros.authenticate(process.argv[3], "", "", "", 0, "", 0); // cbrs reads its update token from the mac field
const run = await call(ros, "/cbrs/run_task", "cbrs/RunTask", { task: "RobotArmServeACup" }, 120000);
found.run = run.status;
found.steps = run.result.plan.steps.length;
const succeeded = () => progress.filter((p) => p.event === "step_succeeded").length;
const deadline = Date.now() + WAIT;
while (succeeded() < found.steps && Date.now() < deadline) {
  await new Promise((resolve) => setTimeout(resolve, 50));
}
found.progress = succeeded();
console.log(JSON.stringify(found));
ros.close();
process.exit(0);
