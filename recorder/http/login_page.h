// The page wirc-recorder shows at /login (and in place of any page) when
// --http-token is set and the request does not carry it: the token goes
// into a cookie the browser then sends with every request, the page's
// scripts, streams and socket included. Nothing is sent to the server in
// a body; the cookie stays on this site (SameSite=Strict).
#pragma once

namespace wircam::recorder {

inline constexpr const char kLoginPage[] = R"html(<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>wirc-recorder: sign in</title>
<meta name="viewport" content="width=device-width, initial-scale=1">
<style>
body { background: #15171a; color: #e8e8e8; font: 16px sans-serif; margin: 0;
       display: flex; min-height: 100vh; align-items: center; justify-content: center; }
form { background: #202328; padding: 24px; border-radius: 8px; width: min(90vw, 360px); }
h1 { font-size: 20px; margin: 0 0 16px; }
input, button { font: inherit; width: 100%; box-sizing: border-box; padding: 10px; margin-top: 8px; }
button { background: #2d6cdf; color: white; border: 0; border-radius: 4px; }
p { color: #aab; font-size: 14px; }
</style></head>
<body>
<form id="login">
  <h1>wirc-recorder</h1>
  <label for="token">Access token (<code>--http-token</code>)</label>
  <input id="token" type="password" autocomplete="current-password" required autofocus>
  <button type="submit">Sign in</button>
  <p id="hint"></p>
</form>
<script>
"use strict";
document.getElementById("login").addEventListener("submit", event => {
  event.preventDefault();
  const token = document.getElementById("token").value.trim();
  document.cookie = `wircam_token=${token}; path=/; SameSite=Strict; max-age=2592000`;
  location.href = "/";
});
if (document.cookie.includes("wircam_token="))
  document.getElementById("hint").textContent = "That token was not accepted.";
</script>
</body></html>
)html";

}  // namespace wircam::recorder
