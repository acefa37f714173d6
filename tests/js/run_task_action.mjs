// roslibjs 2's Action, unchanged, runs a task of a running cbrs server as the /cbrs/run_task action:
// refused without the update token, then one feedback per plan step and the run as the result.
// tests/test_rosbridge_roslibjs.py runs it and asserts on the one line of JSON it prints.
//
//     node tests/js/run_task_action.mjs PORT TOKEN
//
// Every wait is bounded; the script gives up (exit status 2) after 150 s in all.

import { Action, Ros } from "roslib";
import { bounded } from "./bounded.mjs";

const WAIT = 10000;
const RUN = 120000; // a run in the simulated home takes 10-20 s on a busy two-core machine
const url = `ws://127.0.0.1:${Number(process.argv[2])}`;

setTimeout(() => {
  console.error("run_task_action.mjs: gave up after 150 s");
  process.exit(2);
}, 150000).unref();

function run(action, goal, ms) {
  const feedback = [];
  return bounded("run_task goal", ms, (resolve) => {
    action.sendGoal(
      goal,
      (result) => resolve({ feedback, result }),
      (step) => feedback.push(step),
      (error) => resolve({ feedback, failed: String(error) }),
    );
  });
}

const ros = await bounded("connect", WAIT, (resolve, reject) => {
  const connection = new Ros({ url });
  connection.on("connection", () => resolve(connection));
  connection.on("error", (error) => reject(new Error(`connect: ${error?.message ?? error}`)));
});
const action = new Action({ ros, name: "/cbrs/run_task", actionType: "cbrs/action/RunTask" });
const found = {};
found.anonymous = await run(action, { task: "RobotArmServeACup" }, WAIT);
ros.authenticate(process.argv[3], "", "", "", 0, "", 0); // cbrs reads its update token from the mac field
found.run = await run(action, { task: "RobotArmServeACup" }, RUN);
console.log(JSON.stringify(found));
ros.close();
process.exit(0);
