"""A stand-in for browser pages watching the live view (web:=true), for the bench:

  python -m m2wr_tools.bench.web_watch URL [--pages N]

It opens N WebSockets to URL (ws://127.0.0.1:PORT/ws), trying again every 0.2 s until the
simulator serves them, and reads every message as a page does (JSON-decoded); on SIGTERM or
SIGINT prints one JSON line {"pages", "frames", "bytes", "seconds"} and ends. No drawing:
what it costs is what the simulator's server and the wire cost, plus decoding."""
import asyncio
import json
import signal
import sys
import time

import aiohttp

from .. import usage


async def _page(url, counts, stop):
    while not stop.is_set():
        try:
            async with aiohttp.ClientSession() as session:
                async with session.ws_connect(url, max_msg_size=0) as ws:
                    async for msg in ws:
                        if msg.type == aiohttp.WSMsgType.TEXT:
                            message = json.loads(msg.data)
                            counts["bytes"] += len(msg.data)
                            if message.get("type") == "frame":
                                counts["frames"] += 1
        except (aiohttp.ClientError, OSError):
            pass
        try:
            await asyncio.wait_for(stop.wait(), 0.2)
        except asyncio.TimeoutError:
            pass


async def _main(args):
    stop = asyncio.Event()
    loop = asyncio.get_event_loop()
    for sig in (signal.SIGTERM, signal.SIGINT):
        loop.add_signal_handler(sig, stop.set)
    counts = {"pages": args.pages, "frames": 0, "bytes": 0}
    start = time.monotonic()
    tasks = [asyncio.ensure_future(_page(args.url, counts, stop)) for _ in range(args.pages)]
    await stop.wait()
    for task in tasks:
        task.cancel()
    await asyncio.gather(*tasks, return_exceptions=True)
    counts["seconds"] = round(time.monotonic() - start, 2)
    print(json.dumps(counts), flush=True)


def main(argv=None):
    parser = usage.parser("python -m m2wr_tools.bench.web_watch", __doc__, examples=[
        "python -m m2wr_tools.bench.web_watch ws://127.0.0.1:8090/ws --pages 3"],
        exit_statuses="Exit status: 0 after SIGTERM or SIGINT, the counts printed; 2 for bad "
        "arguments.")
    parser.add_argument("url", help="the live view's WebSocket, ws://127.0.0.1:PORT/ws")
    parser.add_argument("--pages", type=int, default=1, help="pages watching at once")
    args = parser.parse_args(argv)
    asyncio.run(_main(args))
    return 0


if __name__ == "__main__":
    sys.exit(main())
