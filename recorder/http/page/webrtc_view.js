// The live picture over WebRTC (WHEP: the offer POSTed, the answer back),
// at a fifth of MJPEG's bitrate and a sixth of its delay. MJPEG shows at
// once, and stays when the browser has no WebRTC, the recorder has it off,
// or the connection does not come up; WebRTC takes over at its first
// frame. The card's head says which one shows. The peer connection also carries the drive
// mode's data channel (control.js), unordered and never retransmitted: a
// lost command is replaced by the next one, never delivered late.
const kWebRtcPatienceMs = 5000;  // to connect, and for the first frame
const kWebRtcRetryMs = 3000, kWebRtcRetryMaxMs = 60000;  // after a failed try
let webrtcOffered = true;        // the recorder's --webrtc (the page's state)

function showTransport(view, transport) {
  view.box.dataset.transport = transport;
  view.transport.textContent = transport === "webrtc" ? "WebRTC" : "MJPEG";
  view.img.hidden = transport === "webrtc";
  view.video.hidden = transport !== "webrtc";
  view.video.classList.remove("warming");
}

function showMjpeg(view, name) {
  showTransport(view, "mjpeg");
  view.img.src = "/live/" + encodeURIComponent(name) + ".mjpg?t=" + Date.now();
}

// Starts the picture of a camera that went live: MJPEG now, WebRTC when
// its first frame is there.
async function startPicture(view, name) {
  stopPicture(view);
  showMjpeg(view, name);
  if (!webrtcOffered || !window.RTCPeerConnection) return;
  const attempt = view.attempt = {};
  let webrtc = null;
  for (let retryMs = kWebRtcRetryMs; ; retryMs = Math.min(2 * retryMs, kWebRtcRetryMaxMs)) {
    webrtc = await connectWebRtc(view, name);
    if (view.attempt !== attempt) {  // stopped or restarted meanwhile
      if (webrtc) closeWebRtc(webrtc);
      return;
    }
    if (webrtc) break;
    // Not up in time (a loaded machine, a network that drops UDP): MJPEG
    // stays, and WebRTC is tried again, less often each time.
    await new Promise(done => setTimeout(done, retryMs));
    if (view.attempt !== attempt) return;
  }
  view.webrtc = webrtc;
  view.img.removeAttribute("src");  // one stream at a time
  showTransport(view, "webrtc");
}

function stopPicture(view) {
  view.attempt = null;
  if (view.webrtc) closeWebRtc(view.webrtc);
  view.webrtc = null;
  view.img.removeAttribute("src");
  view.video.srcObject = null;
}

// A peer connection showing `name` in the card's video, or null.
async function connectWebRtc(view, name) {
  // No ICE servers: the recorder's answer carries its candidates, and no
  // third party is asked anything.
  const pc = new RTCPeerConnection();
  const webrtc = { pc, session: null, drive: null };
  try {
    pc.addTransceiver("video", { direction: "recvonly" });
    if (view.controls)
      webrtc.drive = pc.createDataChannel("drive", { ordered: false, maxRetransmits: 0 });
    pc.ontrack = event => { view.video.srcObject = new MediaStream([event.track]); };
    await pc.setLocalDescription(await pc.createOffer());
    await gathered(pc);
    const response = await fetch(`/api/cameras/${encodeURIComponent(name)}/whep`, {
      method: "POST", headers: { "Content-Type": "application/sdp" },
      body: pc.localDescription.sdp });
    if (response.status !== 201) throw new Error(`WHEP ${response.status}`);
    webrtc.session = response.headers.get("Location");
    await pc.setRemoteDescription({ type: "answer", sdp: await response.text() });
    await connected(pc);
    // Played unseen over the MJPEG picture until its first frame.
    view.video.classList.add("warming");
    view.video.hidden = false;
    await firstFrame(view.video);
    pc.addEventListener("connectionstatechange", () => {
      if (pc.connectionState !== "failed" || view.webrtc !== webrtc) return;
      // Lost on the way (a network change): MJPEG until the state changes.
      closeWebRtc(webrtc);
      view.webrtc = null;
      showMjpeg(view, name);
    });
    return webrtc;
  } catch (error) {
    console.log(`WebRTC for ${name}: ${error.message}; showing MJPEG`);
    closeWebRtc(webrtc);
    view.video.hidden = true;
    view.video.classList.remove("warming");
    view.video.srcObject = null;
    return null;
  }
}

function firstFrame(video) {
  return new Promise((done, fail) => {
    const timer = setTimeout(() => fail(new Error("no frame")), kWebRtcPatienceMs);
    const check = () => video.videoWidth ? (clearTimeout(timer), done()) : setTimeout(check, 20);
    check();
  });
}

function gathered(pc) {
  return new Promise(done => {
    if (pc.iceGatheringState === "complete") return done();
    pc.addEventListener("icegatheringstatechange", () => {
      if (pc.iceGatheringState === "complete") done();
    });
    setTimeout(done, 2000);  // what is there by then
  });
}

function connected(pc) {
  return new Promise((done, fail) => {
    const timer = setTimeout(() => fail(new Error("no connection")), kWebRtcPatienceMs);
    const check = () => {
      if (pc.connectionState === "connected") { clearTimeout(timer); done(); }
      if (pc.connectionState === "failed") { clearTimeout(timer); fail(new Error("failed")); }
    };
    pc.addEventListener("connectionstatechange", check);
    check();
  });
}

// The session ends on the recorder too (WHEP's DELETE), even as the page
// is unloading.
function closeWebRtc(webrtc) {
  webrtc.pc.close();
  if (webrtc.session) fetch(webrtc.session, { method: "DELETE", keepalive: true });
  webrtc.session = null;
}

window.addEventListener("pagehide", () => {
  for (const view of Object.values(views)) if (view.webrtc) closeWebRtc(view.webrtc);
});
