"""A real MCP client against `mprog mcp`: the official Python SDK (`pip install mcp`)
starts the server over stdio, lists its tools, gets a located diagnostic for a broken
program, runs a small program to files and a PNG with fast settings, and is refused a
path escape. Run by tests/mcp_client.rs; usage: client.py MPROG_BINARY OUT_DIR.
Exits non-zero on the first failed check."""

import asyncio
import base64
import json
import os
import sys
import time

from mcp import ClientSession, StdioServerParameters
from mcp.client.stdio import stdio_client

BROKEN = """prompt "a person walks forward"
length 4s
always { r_hnad.y > 1 m }
always { pelvis.z > 1 m }
"""

SMALL = """prompt "a person raises the right hand"
length 1s
at end { r_hand.y > head.y }
"""

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def text_of(result):
    return "".join(c.text for c in result.content if getattr(c, "type", "") == "text")


async def main(exe, out):
    params = StdioServerParameters(
        command=exe, args=["mcp", "--out-dir", out, "--time-limit", "300"]
    )
    passed = 0
    async with stdio_client(params) as (read, write):
        async with ClientSession(read, write) as s:
            await s.initialize()

            tools = sorted(t.name for t in (await s.list_tools()).tools)
            assert tools == ["check", "joints", "library", "run", "score"], tools
            passed += 1

            # Both problems in one round: the misspelt joint (an error, located) and the
            # constraint frame 0 breaks (a warning with its own hint).
            r = await s.call_tool("check", {"source": BROKEN})
            v = json.loads(text_of(r))
            assert v["ok"] is False, v
            codes = [d["code"] for d in v["diagnostics"]]
            assert "mprog::unknown_joint" in codes and "mprog::never_met" in codes, codes
            d = next(d for d in v["diagnostics"] if d["code"] == "mprog::unknown_joint")
            assert (d["line"], d["column"]) == (3, 10), d
            assert "r_hand" in d["hint"], d
            passed += 1

            # A malformed request is a protocol error, and the server lives on.
            try:
                await s.call_tool("check", {"source": 3})
                raise AssertionError("a number as `source` was accepted")
            except AssertionError:
                raise
            except Exception as e:  # the SDK's protocol error type varies by version
                assert "source" in str(e), e
            passed += 1

            start = time.monotonic()
            r = await s.call_tool(
                "run",
                {
                    "source": SMALL,
                    "knobs": {"steps": 4},
                    "baseline": False,
                    "output": ["small/hand.json", "small/hand.bvh"],
                },
            )
            took = time.monotonic() - start
            assert not r.is_error, text_of(r)
            v = json.loads(text_of(r))
            assert v["files"][:2] == ["small/hand.json", "small/hand.bvh"], v["files"]
            for f in v["files"]:
                assert os.path.isfile(os.path.join(out, f)), f
            assert v["statements"][0]["line"] == 3 and v["statements"][0]["guided"] >= 0, v
            images = [c for c in r.content if getattr(c, "type", "") == "image"]
            assert len(images) == 1, r.content
            assert base64.b64decode(images[0].data).startswith(PNG_MAGIC)
            print(f"run: {took:.1f} s for a 1 s motion, 4 guided steps")
            passed += 1

            r = await s.call_tool("run", {"source": SMALL, "output": "../escape.json"})
            assert r.is_error and "refused path" in text_of(r), text_of(r)
            assert not os.path.exists(os.path.join(out, "..", "escape.json"))
            passed += 1

            card = await s.get_prompt("write-mprog")
            assert "joints" in card.messages[0].content.text
            res = await s.read_resource("mprog://prompt-card")
            assert res.contents[0].text == card.messages[0].content.text
            passed += 1
    print(f"mcp client: {passed} passed, 0 failed")


if __name__ == "__main__":
    asyncio.run(main(sys.argv[1], sys.argv[2]))
