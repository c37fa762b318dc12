/**
 * @license
 * three.js r111, the ES module of Debian's libjs-three
 * (/usr/share/javascript/three/three.module.js), embedded by c3po.
 * Copyright 2010-2019 three.js authors (Debian: "Copyright: 2010-2017 three.js authors")
 * SPDX-License-Identifier: MIT
 */
