#!/usr/bin/python3
"""Drop files on an X11 window as a file manager does: the XDND protocol (version 5),
with the files offered as text/uri-list. For the window tests under Xvfb (xdotool cannot
drag and drop between programs). Needs python3-xlib (Debian package python3-xlib).

Usage: scripts/xdnd-drop.py WINDOW_ID FILE...
Exits 0 when the window took the drop (it asked for the file list and said it was
finished), 1 when it did not answer, 2 for bad arguments or a window without XdndAware.
"""
import os
import select
import sys
import time
import urllib.parse

from Xlib import X, Xatom, display
from Xlib.protocol import event

TIMEOUT = 5.0


def main():
    if len(sys.argv) < 3:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    target_id = int(sys.argv[1], 0)
    paths = [os.path.abspath(p) for p in sys.argv[2:]]
    d = display.Display()
    root = d.screen().root
    target = d.create_resource_object("window", target_id)
    atom = lambda name: d.intern_atom(name)
    aware = target.get_full_property(atom("XdndAware"), Xatom.ATOM)
    if aware is None:
        print(f"xdnd-drop: window {target_id:#x} does not accept drops (no XdndAware)", file=sys.stderr)
        return 2
    version = min(5, int(aware.value[0]))
    uri_list = atom("text/uri-list")
    selection = atom("XdndSelection")
    src = root.create_window(0, 0, 1, 1, 0, X.CopyFromParent, X.InputOnly, X.CopyFromParent)
    src.set_selection_owner(selection, X.CurrentTime)
    payload = "".join("file://" + urllib.parse.quote(p) + "\r\n" for p in paths).encode()

    def send(name, data):
        ev = event.ClientMessage(window=target, client_type=atom(name), data=(32, data + [0] * (5 - len(data))))
        target.send_event(ev, event_mask=0)
        d.flush()

    # Where to drop: the window's centre, in root coordinates.
    g = target.get_geometry()
    t = target.translate_coords(root, 0, 0)
    x, y = -t.x + g.width // 2, -t.y + g.height // 2

    send("XdndEnter", [src.id, version << 24, uri_list, 0, 0])
    send("XdndPosition", [src.id, 0, (x << 16) | y, X.CurrentTime, atom("XdndActionCopy")])
    status = finished = asked = False
    dropped = False
    end = time.monotonic() + TIMEOUT
    while time.monotonic() < end and not finished:
        if not d.pending_events():
            select.select([d.fileno()], [], [], 0.05)
            if not d.pending_events():
                continue
        e = d.next_event()
        if e.type == X.ClientMessage and e.client_type == atom("XdndStatus"):
            status = True
            if not dropped:
                send("XdndDrop", [src.id, 0, X.CurrentTime])
                dropped = True
        elif e.type == X.ClientMessage and e.client_type == atom("XdndFinished"):
            finished = True
        elif e.type == X.SelectionRequest:
            asked = True
            prop = e.property if e.property != X.NONE else e.target
            e.requestor.change_property(prop, e.target, 8, payload)
            notify = event.SelectionNotify(
                time=e.time, requestor=e.requestor, selection=e.selection, target=e.target, property=prop
            )
            e.requestor.send_event(notify, event_mask=0)
            d.flush()
    if not dropped:
        send("XdndLeave", [src.id])
    src.destroy()
    d.flush()
    if not (status and asked and finished):
        print(
            f"xdnd-drop: no complete drop (status {status}, asked for the files {asked}, finished {finished})",
            file=sys.stderr,
        )
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
