// roslibjs, unchanged, against the cbrs rosbridge server: the round trips tests/test_rosbridge_roslibjs.py
// asserts on. Prints one line of JSON with what each round trip gave.
//
//     node tests/js/roundtrip.mjs PORT
//
// Every wait is bounded: a step that gets no answer within WAIT ms fails the script (exit status 1).

import { Param, Ros, Service, Topic } from "roslib";
import { bounded as boundedFor } from "./bounded.mjs";

const WAIT = 5000;
const port = Number(process.argv[2]);
const url = `ws://127.0.0.1:${port}`;

setTimeout(() => {
  console.error("roundtrip.mjs: gave up after 30 s");
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

// A failed call resolves to {failed: <the error text>}, so results can record it.
function call(service, request) {
  return bounded(`call ${service.name}`, (resolve) =>
    service.callService(request, resolve, (error) => resolve({ failed: error })),
  );
}

function rosapi(what, method, ...args) {
  return bounded(what, (resolve, reject) => method(...args, resolve, reject));
}

async function until(condition, step) {
  const deadline = Date.now() + WAIT;
  while (!(await condition())) {
    if (Date.now() > deadline) return false;
    if (step) step();
    await new Promise((resolve) => setTimeout(resolve, 50));
  }
  return true;
}

async function main() {
  const results = {};
  const a = await connect();
  const b = await connect();
  results.connected = a.isConnected && b.isConnected;

  const heard = [];
  const listener = new Topic({ ros: b, name: "/chatter", messageType: "std_msgs/String" });
  listener.subscribe((message) => heard.push(message.data));
  const talker = new Topic({ ros: a, name: "/chatter", messageType: "std_msgs/String" });
  talker.advertise();
  // b's subscribe and a's publish travel on different connections: ping until b hears one
  results.subscribed = await until(
    () => heard.includes("ping"),
    () => talker.publish({ data: "ping" }),
  );
  for (const text of ["one", "two", "three"]) talker.publish({ data: text });
  await until(() => heard.includes("three"));
  results.heard = heard.filter((text) => text !== "ping");
  const topics = await rosapi("getTopics", a.getTopics.bind(a));
  results.topics = [...topics.topics].sort();
  results.topic_type = await rosapi("getTopicType", a.getTopicType.bind(a), "/chatter");

  results.add = await call(new Service({ ros: b, name: "/test/add", serviceType: "test/Add" }), { a: 2, b: 3 });
  results.refuse = await call(new Service({ ros: b, name: "/test/refuse", serviceType: "test/Refuse" }), {});

  const provider = new Service({ ros: a, name: "/test/upper", serviceType: "test/Upper" });
  await provider.advertise((request, response) => {
    response.text = request.text.toUpperCase();
    return true;
  });
  const folded = new Service({ ros: a, name: "/test/fold", serviceType: "test/Fold" });
  await folded.advertiseAsync(async () => {
    throw new Error("the arm is folded");
  });
  const services = () => rosapi("getServices", b.getServices.bind(b));
  results.advertised = await until(async () => (await services()).includes("/test/fold"));
  results.upper = await call(new Service({ ros: b, name: "/test/upper", serviceType: "test/Upper" }), { text: "hello" });
  results.fold = await call(new Service({ ros: b, name: "/test/fold", serviceType: "test/Fold" }), {});
  results.service_type = await rosapi("getServiceType", b.getServiceType.bind(b), "/test/upper");

  const gain = new Param({ ros: a, name: "/test/gain" });
  await bounded("Param.set", (resolve, reject) => gain.set({ k: [1, 2.5], on: true }, resolve, reject));
  const same = new Param({ ros: b, name: "test/gain" });
  results.param = await bounded("Param.get", (resolve, reject) => same.get(resolve, reject));
  results.params = await rosapi("getParams", b.getParams.bind(b));
  await bounded("Param.delete", (resolve, reject) => same.delete(resolve, reject));
  results.deleted = await bounded("Param.get", (resolve) => same.get(resolve, (reason) => resolve({ failed: reason })));

  listener.unsubscribe();
  talker.unadvertise();
  await provider.unadvertise();
  await folded.unadvertise();
  a.close();
  b.close();
  return results;
}

main().then(
  (results) => process.stdout.write(`${JSON.stringify(results)}\n`, () => process.exit(0)),
  (error) => {
    console.error(`roundtrip.mjs: ${error?.stack ?? error}`);
    process.exit(1);
  },
);
