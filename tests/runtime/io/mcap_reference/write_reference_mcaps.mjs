// Writes the reference MCAP files read by test_rosbag2_reader, with the MCAP project's own TypeScript
// writer (@mcap/core), so that our reader is checked against files it did not write itself. Each file
// gets a JSON sidecar with its topics and every message (topic, log time, payload in hex) in the order
// written. The payloads are real ROS 2 CDR: a 4x2 mono8 sensor_msgs/msg/Image and a 3-point
// sensor_msgs/msg/PointCloud2 (x, y, z float32), header stamps set.
//
// Regenerate (README.md): cd tests/runtime/io/mcap_reference && npm ci && node write_reference_mcaps.mjs &&
//   rm -rf node_modules
import { CdrWriter } from "@foxglove/cdr";
import zstd from "@foxglove/wasm-zstd";
import { McapWriter } from "@mcap/core";
import lz4 from "lz4js";
import { writeFileSync } from "node:fs";

const IMAGE_MSG = `std_msgs/Header header
uint32 height
uint32 width
string encoding
uint8 is_bigendian
uint32 step
uint8[] data
================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
`;
const CLOUD_MSG = `std_msgs/Header header
uint32 height
uint32 width
PointField[] fields
bool is_bigendian
uint32 point_step
uint32 row_step
uint8[] data
bool is_dense
================================================================================
MSG: sensor_msgs/PointField
string name
uint32 offset
uint8 datatype
uint32 count
`;
const QOS = "- history: 3\n  depth: 0\n  reliability: 1\n  durability: 2\n";
const BASE_NS = 1700000000n * 1000000000n;

function writeHeader(cdr, stampNs, frameId) {
  cdr.int32(Number(stampNs / 1000000000n));
  cdr.uint32(Number(stampNs % 1000000000n));
  cdr.string(frameId);
}

// A 4x2 mono8 image whose pixels depend on i.
function imageCdr(i, stampNs) {
  const cdr = new CdrWriter();
  writeHeader(cdr, stampNs, "camera");
  cdr.uint32(2).uint32(4).string("mono8").uint8(0).uint32(4);
  cdr.uint8Array(Uint8Array.from({ length: 8 }, (_, k) => (i * 16 + k * 7) & 0xff));
  return cdr.data;
}

// Three points (x, y, z float32, point_step 12) whose coordinates depend on i.
function cloudCdr(i, stampNs) {
  const cdr = new CdrWriter();
  writeHeader(cdr, stampNs, "lidar");
  cdr.uint32(1).uint32(3);
  cdr.sequenceLength(3);
  ["x", "y", "z"].forEach((name, k) => cdr.string(name).uint32(4 * k).uint8(7).uint32(1));
  cdr.uint8(0).uint32(12).uint32(36);
  const points = new Float32Array([1 + i, 0.5, -0.25, 2, 1.5 * i, 0.75, -3, 0, 0.125 * i]);
  cdr.uint8Array(new Uint8Array(points.buffer));
  cdr.uint8(1);
  return cdr.data;
}

// An IWritable collecting the file in memory.
class MemoryWritable {
  chunks = [];
  length = 0n;
  position() {
    return this.length;
  }
  async write(buffer) {
    this.chunks.push(Buffer.from(buffer));
    this.length += BigInt(buffer.byteLength);
  }
  bytes() {
    return Buffer.concat(this.chunks);
  }
}

const COMPRESSORS = {
  zstd: (data) => ({ compression: "zstd", compressedData: new Uint8Array(zstd.compress(data, 3)) }),
  lz4: (data) => ({ compression: "lz4", compressedData: new Uint8Array(lz4.compress(data)) }),
  none: undefined,
};

// Ten images at 20 Hz and ten clouds at 10 Hz on two channels, interleaved; the cloud at i = 4 is
// written after the image that follows it in log time (out of order, as a recorder may receive it).
function messagePlan() {
  const plan = [];
  for (let i = 0; i < 10; ++i) {
    const imageTime = BASE_NS + BigInt(i) * 50000000n;
    const cloudTime = BASE_NS + BigInt(i) * 100000000n + 1000000n;
    plan.push({ topic: "/camera/image_raw", logTime: imageTime, data: imageCdr(i, imageTime - 3000000n) });
    plan.push({ topic: "/lidar/points", logTime: cloudTime, data: cloudCdr(i, cloudTime - 2000000n) });
  }
  plan.sort((a, b) => (a.logTime < b.logTime ? -1 : a.logTime > b.logTime ? 1 : 0));
  const late = plan.findIndex((m) => m.topic === "/lidar/points" && m.logTime === BASE_NS + 401000000n);
  [plan[late], plan[late + 1]] = [plan[late + 1], plan[late]];
  return plan;
}

async function addChannels(writer) {
  const topics = [
    { name: "/camera/image_raw", type: "sensor_msgs/msg/Image", definition: IMAGE_MSG },
    { name: "/lidar/points", type: "sensor_msgs/msg/PointCloud2", definition: CLOUD_MSG },
  ];
  const ids = {};
  for (const topic of topics) {
    const schemaId = await writer.registerSchema({
      name: topic.type, encoding: "ros2msg", data: new TextEncoder().encode(topic.definition),
    });
    ids[topic.name] = await writer.registerChannel({
      topic: topic.name, schemaId, messageEncoding: "cdr",
      metadata: new Map([["offered_qos_profiles", QOS]]),
    });
  }
  return { topics, ids };
}

async function writeReference(name, options) {
  const writable = new MemoryWritable();
  const writer = new McapWriter({ writable, ...options });
  await writer.start({ profile: "ros2", library: "@mcap/core reference writer" });
  const { topics, ids } = await addChannels(writer);
  const plan = messagePlan();
  for (const [sequence, m] of plan.entries()) {
    await writer.addMessage({
      channelId: ids[m.topic], sequence, logTime: m.logTime, publishTime: m.logTime, data: m.data,
    });
  }
  await writer.end();
  writeFileSync(`${name}.mcap`, writable.bytes());
  const sidecar = {
    topics: topics.map((t) => ({ name: t.name, type: t.type, serialization_format: "cdr" })),
    messages: plan.map((m) => ({
      topic: m.topic, log_time_ns: m.logTime.toString(), data_hex: Buffer.from(m.data).toString("hex"),
    })),
  };
  writeFileSync(`${name}.json`, JSON.stringify(sidecar, null, 1) + "\n");
}

await zstd.isLoaded;
// Small chunks, so that every chunked file has several and the late cloud crosses a chunk boundary.
await writeReference("zstd_chunked", { chunkSize: 600, compressChunk: COMPRESSORS.zstd });
await writeReference("lz4_chunked", { chunkSize: 600, compressChunk: COMPRESSORS.lz4 });
await writeReference("uncompressed_chunked", { chunkSize: 600, compressChunk: COMPRESSORS.none });
await writeReference("unchunked", { useChunks: false, useChunkIndex: false });
