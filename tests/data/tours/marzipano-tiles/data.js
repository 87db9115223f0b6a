// A Marzipano tool export in miniature: the tool's data.js fields and its tiles/ layout
// (tiles/<id>/{z}/{f}/{y}/{x}.jpg, preview.jpg), tiles made from ../pannellum/*.jpg.
// How it was made: README.md beside this file.
var APP_DATA = {
  "scenes": [
    {
      "id": "0-courtyard",
      "name": "Courtyard",
      "levels": [
        {
          "tileSize": 16,
          "size": 16,
          "fallbackOnly": true
        },
        {
          "tileSize": 16,
          "size": 32
        },
        {
          "tileSize": 48,
          "size": 96
        }
      ],
      "faceSize": 96,
      "initialViewParameters": {
        "yaw": 0.3490658503988659,
        "pitch": 0.08726646259971647,
        "fov": 1.3089969389957472
      },
      "linkHotspots": [
        {
          "yaw": 1.0471975511965976,
          "pitch": 0.03490658503988659,
          "rotation": 0,
          "target": "1-interior"
        }
      ],
      "infoHotspots": [
        {
          "yaw": -0.6981317007977318,
          "pitch": -0.17453292519943295,
          "title": "Courtyard",
          "text": "CC0, Greg Zaal."
        }
      ]
    },
    {
      "id": "1-interior",
      "name": "Interior",
      "levels": [
        {
          "tileSize": 32,
          "size": 32
        },
        {
          "tileSize": 32,
          "size": 64
        }
      ],
      "faceSize": 64,
      "initialViewParameters": {
        "yaw": -0.5235987755982988,
        "pitch": 0,
        "fov": 1.5707963267948966
      },
      "linkHotspots": [
        {
          "yaw": -2.0943951023931953,
          "pitch": 0,
          "rotation": 3.141592653589793,
          "target": "0-courtyard"
        }
      ],
      "infoHotspots": []
    }
  ],
  "name": "Marzipano tiles test tour",
  "settings": {
    "mouseViewMode": "drag",
    "autorotateEnabled": false,
    "fullscreenButton": false,
    "viewControlButtons": false
  }
};
