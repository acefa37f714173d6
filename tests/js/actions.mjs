// roslibjs 2's Action, unchanged, against the cbrs rosbridge server: a server action, an unknown one,
// and an action another roslibjs client provides (advertise, feedback, succeeded, failed, canceled).
// tests/test_rosbridge_roslibjs.py runs it and asserts on the one line of JSON it prints.
//
//     node tests/js/actions.mjs PORT
//
// Every wait is bounded: a step that gets no answer within WAIT ms fails the script (exit status 1).

import { Action, Ros, Service } from "roslib";
import { bounded as boundedFor } from "./bounded.mjs";

const WAIT = 5000;
const url = `ws://127.0.0.1:${Number(process.argv[2])}`;

setTimeout(() => {
  console.error("actions.mjs: gave up after 30 s");
  process.exit(2);
}, 30000).unref();

function bounded(what, executor) {
  return boundedFor(what, WAIT, executor);
}

function connect() {
  return bounded("connect", (resolve, reject) => {
    const ros = new Ros({ url });
    ros.on("connection", () => resolve(ros));
    ros.on("error", (error) => reject(new Error(`connect: ${error?.message ?? error}`)));
  });
}

// A goal's end as roslibjs reports it: {result} from the result callback, {failed} from the failed one,
// with the feedback heard before.
function send(action, goal, each = (feedback) => feedback) {
  const heard = [];
  return bounded(`goal of ${action.name}`, (resolve) => {
    action.sendGoal(
      goal,
      (result) => resolve({ feedback: heard, result }),
      (feedback) => heard.push(each(feedback)),
      (error) => resolve({ feedback: heard, failed: String(error) }),
    );
  });
}

async function listed(ros, name) {
  const servers = new Service({ ros, name: "/rosapi/action_servers", serviceType: "rosapi/GetActionServers" });
  const deadline = Date.now() + WAIT;
  while (Date.now() < deadline) {
    const answer = await bounded("action_servers", (resolve, reject) => servers.callService({}, resolve, reject));
    if (answer.action_servers.includes(name)) return true;
    await new Promise((resolve) => setTimeout(resolve, 50));
  }
  return false;
}

const found = {};
const caller = await connect();
const provider = await connect();
const type = "example_interfaces/action/Fibonacci";

const count = new Action({ ros: caller, name: "/test/count", actionType: "test/action/Count" });
found.count = await send(count, { to: 3 }, (f) => f.n);
found.unknown = await send(new Action({ ros: caller, name: "/no/such/action", actionType: type }), { order: 1 });

const served = new Action({ ros: provider, name: "/fibonacci", actionType: type });
served.advertise(
  (goal, id) => {
    if (goal.order < 0) {
      served.setFailed(id);
      return;
    }
    if (goal.order > 100) return; // runs until cancelled
    const sequence = [0, 1];
    for (let i = 1; i < goal.order; i++) {
      sequence.push(sequence[i] + sequence[i - 1]);
      served.sendFeedback(id, { sequence: [...sequence] });
    }
    served.setSucceeded(id, { sequence });
  },
  (id) => served.setCanceled(id, { sequence: [] }),
);
found.listed = await listed(caller, "/fibonacci");
const fibonacci = new Action({ ros: caller, name: "/fibonacci", actionType: type });
found.fibonacci = await send(fibonacci, { order: 4 }, (f) => f.sequence.length);
found.failed = await send(fibonacci, { order: -1 });
found.cancelled = await bounded("cancelled goal", (resolve) => {
  const id = fibonacci.sendGoal(
    { order: 1000 },
    (result) => resolve({ result }),
    () => {},
    (error) => resolve({ failed: String(error) }),
  );
  fibonacci.cancelGoal(id);
});
served.unadvertise();
console.log(JSON.stringify(found));
caller.close();
provider.close();
process.exit(0);
