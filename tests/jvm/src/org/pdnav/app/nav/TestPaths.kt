package org.pdnav.app.nav

import java.io.File

/** Paths handed in by tools/android-host/run (surefire system properties). */
object TestPaths {
    private fun prop(name: String): String {
        val v = System.getProperty(name)
        check(!v.isNullOrEmpty()) { "system property $name not set (run the JVM tests through tools/android-host/run)" }
        return v
    }

    /** A file under ../shared/data; fails loudly when absent (never a silent skip). */
    fun sharedData(rel: String): File {
        val f = File(prop("pdnav.shared.data"), rel)
        check(f.isFile) { "shared data missing: $f (put ../shared beside the project root)" }
        return f
    }

    /** A folder of the shared data (a logger's export). */
    fun sharedDir(rel: String): File {
        val f = File(prop("pdnav.shared.data"), rel)
        check(f.isDirectory) { "shared data missing: $f (put ../shared beside the project root)" }
        return f
    }

    /** A fresh, empty scratch directory for one test. */
    fun scratch(name: String): File {
        val d = File(prop("pdnav.scratch"), name)
        d.deleteRecursively()
        check(d.mkdirs()) { "cannot create $d" }
        return d
    }

    /** The host-built pdnav CLI. */
    fun cli(): File {
        val f = File(prop("pdnav.cli"))
        check(f.canExecute()) { "pdnav CLI not built: $f" }
        return f
    }
}
