"""A Wi-Fi-like link between the hosts of scripts/fleet-hosts where the kernel has no netem qdisc:
a switch in user space. It runs in the switch namespace, reads every frame a host sends (a packet
socket on each host's veth end), learns which host has which MAC address, drops a frame with
probability `loss` and forwards the others after a delay drawn uniformly from delay +- jitter,
as `tc netem delay D J loss L%` on every host's interface does (one delay and one loss chance per
host-to-host hop; frames may overtake each other, as with netem's jitter).

Frames keep their virtio-net header (PACKET_VNET_HDR), so TCP segmentation and checksum offload
go through unchanged: a veth hands over 64 KB TCP segments with their checksums not yet filled in.
"""
import heapq
import random
import re
import select
import socket
import time

ETH_P_ALL = 0x0003
SOL_PACKET = 263
PACKET_VNET_HDR = 15
PACKET_OUTGOING = 4          # sll_pkttype of a frame this machine sent (our own forwards)
VNET_HDR = 10                # struct virtio_net_hdr
BUFFER = 65536 + VNET_HDR + 64


class LinkSpec(object):
    """delay and jitter [s], loss [0..1]."""

    def __init__(self, delay=0.0, jitter=0.0, loss=0.0):
        self.delay, self.jitter, self.loss = delay, jitter, loss

    def __repr__(self):
        return "delay %g ms +- %g ms, loss %g %%" % (self.delay * 1e3, self.jitter * 1e3, self.loss * 100)


def parse_netem(text):
    """LinkSpec from tc netem's words: "delay 20ms [10ms] [loss 0.5%]". ValueError naming what
    it cannot read (only these words: a user-space switch is no full netem)."""
    words = text.split()
    spec = LinkSpec()
    i = 0

    def duration(word):
        m = re.match(r"^([0-9.]+)(ms|us|s)$", word)
        if not m:
            raise ValueError("netem %r: %r is not a duration (e.g. 20ms)" % (text, word))
        return float(m.group(1)) * {"ms": 1e-3, "us": 1e-6, "s": 1.0}[m.group(2)]

    while i < len(words):
        if words[i] == "delay" and i + 1 < len(words):
            spec.delay = duration(words[i + 1])
            i += 2
            if i < len(words) and re.match(r"^[0-9.]+(ms|us|s)$", words[i]):
                spec.jitter = duration(words[i])
                i += 1
        elif words[i] == "loss" and i + 1 < len(words):
            m = re.match(r"^([0-9.]+)%$", words[i + 1])
            if not m:
                raise ValueError("netem %r: loss %r is not a percentage (e.g. 0.5%%)" % (text, words[i + 1]))
            spec.loss = float(m.group(1)) / 100.0
            i += 2
        else:
            raise ValueError("netem %r: %r not understood (the user-space link knows delay D [J] and loss P%%)"
                             % (text, words[i]))
    if spec.jitter > spec.delay:
        raise ValueError("netem %r: jitter larger than the delay" % text)
    return spec


class Switch(object):
    """The learning switch with delay and loss; `ports`: interface names (in this namespace)."""

    def __init__(self, ports, spec, seed=None):
        self.spec = spec
        self.random = random.Random(seed)
        self.sockets = {}
        for name in ports:
            s = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.htons(ETH_P_ALL))
            s.setsockopt(SOL_PACKET, PACKET_VNET_HDR, 1)
            s.bind((name, 0))
            s.setblocking(False)
            self.sockets[name] = s
        self.by_fd = {s.fileno(): name for name, s in self.sockets.items()}
        self.where = {}            # MAC -> port
        self.queue = []            # (due, seq, port, frame with its vnet header)
        self.seq = 0
        self.frames = self.dropped = self.sent = 0

    def receive(self, name, now):
        s = self.sockets[name]
        while True:
            try:
                data, address = s.recvfrom(BUFFER)
            except (BlockingIOError, InterruptedError):
                return
            if address[2] == PACKET_OUTGOING or len(data) < VNET_HDR + 14:
                continue
            self.frames += 1
            destination, source = data[VNET_HDR:VNET_HDR + 6], data[VNET_HDR + 6:VNET_HDR + 12]
            self.where[source] = name
            if self.random.random() < self.spec.loss:
                self.dropped += 1
                continue
            due = now + self.spec.delay + self.random.uniform(-self.spec.jitter, self.spec.jitter)
            port = self.where.get(destination)
            for out in ([port] if port is not None and port != name else
                        [p for p in self.sockets if p != name]):
                self.seq += 1
                heapq.heappush(self.queue, (due, self.seq, out, data))

    def send_due(self, now):
        while self.queue and self.queue[0][0] <= now:
            _, _, out, data = heapq.heappop(self.queue)
            try:
                self.sockets[out].send(data)
                self.sent += 1
            except OSError:
                self.dropped += 1  # the host's end is gone (shutting down)

    def counts(self):
        return "%d frames from the hosts, %d lost (%.2f %%), %d sent" % (
            self.frames, self.dropped, 100.0 * self.dropped / max(1, self.frames), self.sent)

    def run(self, should_stop=lambda: False):
        fds = list(self.by_fd)
        while not should_stop():
            now = time.monotonic()
            timeout = 0.2 if not self.queue else max(0.0, self.queue[0][0] - now)
            readable, _, _ = select.select(fds, [], [], timeout)
            now = time.monotonic()
            for fd in readable:
                self.receive(self.by_fd[fd], now)
            self.send_due(time.monotonic())
