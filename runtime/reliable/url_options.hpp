// The URL parameters of the reliable layer and of loss injection on udpm:// (read by the LCM bus, and
// removed from the URL before LCM sees it):
//   reliable=0|1     fragments, NACKs and re-sending (default 1 on udpm://); 0: plain LCM on the wire,
//                    for LCM's own tools (lcm-spy, lcm-logger) and other LCM programs
//   fragment_kb=N    payload per fragment (default 60: one datagram on loopback; 8 on a LAN with
//                    MTU 1500 loses less per lost packet)
//   history_mb=N     what a publisher keeps for answering NACKs (default 64)
//   give_up_s=S      a gap nobody answers is given up after S seconds (default 10; the publisher died)
//   loss=P           test only: drop received datagrams with probability P
//   jitter_ms=J      test only: hold each received message back by 0..J ms
//   loss_seed=N      the seed of loss and jitter (default: from the process id)
#pragma once

#include <cstdint>
#include <string>

#include "runtime/reliable/receiver.hpp"
#include "runtime/reliable/sender.hpp"

namespace fusecal::reliable {

struct UrlOptions {
  bool reliable = true;
  SenderOptions sender;
  ReceiverOptions receiver;
  double loss = 0;
  int64_t jitter_us = 0;
  uint64_t loss_seed = 0;
  std::string lcm_url;  // the URL without these parameters
};

// Throws std::invalid_argument naming the parameter for a value that is not a number or out of range.
UrlOptions ParseUrlOptions(const std::string& url);

}  // namespace fusecal::reliable
